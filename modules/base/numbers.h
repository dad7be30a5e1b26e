// Numeric constants shared by every layer (base is the only module all of them use).
#pragma once

namespace selfcal {

inline constexpr double kPi = 3.14159265358979323846;

}  // namespace selfcal
