// A number as a message names it: at most 6 significant digits (printf's %.6g), e.g. "0.001", "1200",
// "1e-300". The readers' refusals quote the value a file gave with it.
#pragma once

#include <cstdio>
#include <string>

namespace selfcal {

inline std::string ShortNumber(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.6g", v);
  return buffer;
}

}  // namespace selfcal
