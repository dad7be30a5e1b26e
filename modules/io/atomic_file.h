// File access for io: the shared atomic writes and size-capped reads of base/atomic_file.h, under the
// names io's callers use.
#pragma once

#include "base/atomic_file.h"

namespace selfcal::io {

using ::selfcal::ReadFileCapped;
using ::selfcal::WriteFileAtomically;

}  // namespace selfcal::io
