// User text in messages. Every error and warning is one line; any text that came from the
// user (JSON keys and strings, ids, file paths, numbers as typed, command-line arguments) goes
// through one of these so that it can neither split the line, reach the terminal as an escape
// sequence, nor make the line unbounded.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace kr {

// Default bound on the bytes of user text shown in one message.
constexpr size_t kQuotedTextBytes = 80;

// `text` in double quotes: `"` and `\` escaped, \n \r \t as such, other control bytes, DEL
// and bytes that are not UTF-8 as \xHH, C1 controls and the Unicode line separators as \uHHHH.
// Text longer than max_bytes is cut there (never inside a UTF-8 character) and followed by
// an ellipsis and its length: "abc"... (1048576 bytes).
std::string quote_user_text(std::string_view text, size_t max_bytes = kQuotedTextBytes);

// `text` itself when it is printable UTF-8 of at most max_bytes (the common file path or
// JSON pointer reads as it always did), else quote_user_text(text, max_bytes).
std::string show_user_text(std::string_view text, size_t max_bytes = 2 * kQuotedTextBytes);

// `text` as valid UTF-8 for a file that must hold it (a JSON string): every byte that is not
// part of well-formed UTF-8 written as the four characters \xHH, the rest kept as it is.
std::string utf8_escaped(std::string_view text);

}  // namespace kr
