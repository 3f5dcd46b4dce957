// UTF-8 validation for text that ends up in JSON (stats.json, run.json) or messages.
#pragma once
#include <cstddef>
#include <string>
#include <string_view>

namespace shellmpm {

/// Byte offset of the first byte that does not start or continue a well-formed UTF-8
/// sequence (RFC 3629: no overlong forms, no surrogates, nothing above U+10FFFF), or
/// std::string_view::npos when `text` is valid UTF-8.
std::size_t first_invalid_utf8(std::string_view text);

/// Where the first invalid byte is, for messages: its 1-based line and column (in bytes)
/// and the byte as "0xE9". `offset` is what first_invalid_utf8 returned (not npos).
struct Utf8Error {
  int line = 1;
  std::size_t column = 1;
  std::string byte_hex;
};
Utf8Error locate_utf8_error(std::string_view text, std::size_t offset);

}  // namespace shellmpm
