// Text from outside selfcal (a robot controller's messages and identity, a user's file) made safe to
// print on a terminal: control characters could otherwise clear the screen, move the cursor, ring the
// bell or hide what follows (an ANSI escape "\x1b[2J" clears the screen; a NUL or CR hides the rest).
#pragma once

#include <string>
#include <string_view>

namespace selfcal {

// `text` with every control character (C0 0x00-0x1f except TAB and LF, DEL 0x7f, and the C1 controls
// U+0080-U+009F) written as a visible escape: "\x00", "\x1b", "\x0d", "\x07" (C1 as "\u0085"); bytes
// that are not valid UTF-8 as "\xNN" too. A backslash stays as it is; printable UTF-8 (accents, CJK,
// symbols) is kept unchanged.
std::string TerminalSafe(std::string_view text);

}  // namespace selfcal
