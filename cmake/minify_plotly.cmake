# Minifies plotly.js for report.html (about 8.6 MB -> 3.8 MB): Debian 12 ships only the unminified file.
#   cmake -DESBUILD=/usr/bin/esbuild -DINPUT=plotly.js -DOUTPUT=plotly.min.js -P minify_plotly.cmake
# esbuild drops the licence header (it is not marked @license), so the header comment of the input is put
# back on top: plotly.js is MIT-licensed and its notice travels with every copy.
execute_process(COMMAND "${ESBUILD}" "${INPUT}" --minify --log-level=warning
  OUTPUT_VARIABLE minified RESULT_VARIABLE rc ERROR_VARIABLE errors)
if(NOT rc EQUAL 0 OR minified STREQUAL "")
  message(FATAL_ERROR "esbuild could not minify ${INPUT}: ${errors}")
endif()
file(READ "${INPUT}" head LIMIT 4096)
string(FIND "${head}" "*/" end)
if(head MATCHES "^/\\*" AND end GREATER 0)
  string(SUBSTRING "${head}" 0 ${end} banner)
  set(banner "${banner}*/\n")
else()
  set(banner "")
endif()
file(WRITE "${OUTPUT}.tmp" "${banner}${minified}")
file(RENAME "${OUTPUT}.tmp" "${OUTPUT}")
