# selfcal_add_module(NAME <m> SRCS ... [DEPS ...] [PRIVATE_DEPS ...])
#   One static library per module, target selfcal_<m>, alias selfcal::<m>.
#   DEPS are public (other selfcal modules or header-level libraries such as Eigen);
#   PRIVATE_DEPS stay inside the module (Ceres, OpenCV, yaml-cpp ...).
function(selfcal_add_module)
  cmake_parse_arguments(ARG "" "NAME" "SRCS;DEPS;PRIVATE_DEPS" ${ARGN})
  set(target selfcal_${ARG_NAME})
  add_library(${target} STATIC ${ARG_SRCS})
  add_library(selfcal::${ARG_NAME} ALIAS ${target})
  target_include_directories(${target} PUBLIC ${PROJECT_SOURCE_DIR}/modules)
  target_link_libraries(${target} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  selfcal_set_warnings(${target})
  selfcal_set_unity(${target})
endfunction()

# selfcal_add_module_test(NAME <m> SRCS ... [DEPS ...] [LABELS ...])
#   One gtest binary per module, registered test by test with gtest_discover_tests. It links the module
#   selfcal::<m> (and so what the module links), selfcal::test_support and GTest; DEPS adds test support
#   (selfcal::test_worlds) or third-party libraries, never another selfcal module: a module's tests use
#   only what the module itself may use (tests that check one module against another live in
#   test/cross_module).
function(selfcal_add_module_test)
  cmake_parse_arguments(ARG "" "NAME" "SRCS;DEPS;LABELS" ${ARGN})
  if(NOT SELFCAL_BUILD_TESTS)
    return()
  endif()
  foreach(dep ${ARG_DEPS})
    string(REGEX REPLACE "^selfcal::" "" name "${dep}")
    if(NOT name STREQUAL dep AND name IN_LIST SELFCAL_MODULE_ORDER)  # modules/CMakeLists.txt
      message(FATAL_ERROR "${ARG_NAME}_test: DEPS ${dep}: a module's test links only its module (selfcal::${ARG_NAME}) "
        "and what that links; add ${dep} to the module's DEPS if its sources use it, or test the pair in test/cross_module")
    endif()
  endforeach()
  set(target ${ARG_NAME}_test)
  add_executable(${target} ${ARG_SRCS})
  target_link_libraries(${target} PRIVATE selfcal::${ARG_NAME} ${ARG_DEPS} selfcal::test_support GTest::gtest
    GTest::gtest_main)
  target_compile_definitions(${target} PRIVATE
    SELFCAL_SOURCE_DIR="${SELFCAL_SOURCE_DIR}"
    SELFCAL_SHARED_DATA_DIR="${SELFCAL_SHARED_DATA_DIR}")
  selfcal_set_warnings(${target})
  if(NOT ARG_LABELS)
    set(ARG_LABELS unit)
  endif()
  gtest_discover_tests(${target} PROPERTIES LABELS "${ARG_LABELS}" DISCOVERY_TIMEOUT 60)
endfunction()

function(selfcal_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra)
  if(SELFCAL_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

# The sources of `target` compiled in batches of up to 16 (SELFCAL_UNITY_BUILD): names at namespace scope
# in a source's anonymous namespace must then be unique within its module.
function(selfcal_set_unity target)
  set_target_properties(${target} PROPERTIES UNITY_BUILD ${SELFCAL_UNITY_BUILD} UNITY_BUILD_BATCH_SIZE 16)
endfunction()
