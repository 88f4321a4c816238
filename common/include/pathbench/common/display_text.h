#pragma once
// Text that came from input (benchmark and scene names, paths, strings of a file's
// context, error messages quoting them) as it may be shown. A name is data: printed raw,
// an ESC or OSC sequence in it would drive the terminal (retitle it, hide or rewrite
// lines) and a CR or LF would forge a line of the table around it. So every string
// pathbench prints that it did not write itself goes through one of these:
//   terminal_safe   for a terminal (text tables, messages on stderr)
//   markdown_text   for Markdown prose (a list item, a table cell outside code)
//   markdown_code   for a Markdown code span in a table cell (`name`)
// terminal_safe shows as escapes: C0 controls and DEL (\n \r \t \e, else \xHH), the C1
// controls U+0080..U+009F (\u{9b}: some terminals take U+009B as CSI), bytes that are not
// UTF-8 (\xHH), and the code points that reorder or break lines without being visible
// (bidirectional overrides and isolates, U+2028/9, U+FEFF: \u{202e}). Everything else,
// including all printable Unicode, passes unchanged. Header-only: common, analysis and
// the command line all use it.
#include <cstdint>
#include <string>
#include <string_view>

namespace pb {

namespace display_detail {

// Length of the well-formed UTF-8 sequence at s[i] and its code point; 0 when the byte
// there does not start one (a stray continuation byte, an overlong form, a surrogate,
// a code point above U+10FFFF, or a sequence cut short).
inline size_t utf8_sequence(std::string_view s, size_t i, uint32_t& cp) {
  const auto byte = [&](size_t k) { return static_cast<uint8_t>(s[k]); };
  const uint8_t b0 = byte(i);
  size_t n;
  uint8_t lo = 0x80, hi = 0xBF;  // the range of the second byte
  if (b0 >= 0xC2 && b0 <= 0xDF) n = 2, cp = b0 & 0x1Fu;
  else if (b0 >= 0xE0 && b0 <= 0xEF) n = 3, cp = b0 & 0x0Fu, lo = b0 == 0xE0 ? 0xA0 : 0x80, hi = b0 == 0xED ? 0x9F : 0xBF;
  else if (b0 >= 0xF0 && b0 <= 0xF4) n = 4, cp = b0 & 0x07u, lo = b0 == 0xF0 ? 0x90 : 0x80, hi = b0 == 0xF4 ? 0x8F : 0xBF;
  else return 0;
  if (i + n > s.size()) return 0;
  for (size_t k = 1; k < n; ++k) {
    const uint8_t b = byte(i + k);
    if (b < (k == 1 ? lo : 0x80) || b > (k == 1 ? hi : 0xBF)) return 0;
    cp = (cp << 6) | (b & 0x3Fu);
  }
  return n;
}

// Invisible code points that reorder text or start a line.
inline bool invisible_control(uint32_t cp) {
  return (cp >= 0x80 && cp <= 0x9F) || cp == 0x061C || cp == 0x200E || cp == 0x200F || (cp >= 0x202A && cp <= 0x202E) ||
         (cp >= 0x2066 && cp <= 0x2069) || cp == 0x2028 || cp == 0x2029 || cp == 0xFEFF;
}

inline void hex_byte(std::string& out, uint8_t b) {
  static const char* const kHex = "0123456789abcdef";
  out += "\\x";
  out += kHex[b >> 4];
  out += kHex[b & 15];
}

}  // namespace display_detail

// `s` with every control character, invisible reordering code point and non-UTF-8 byte
// shown as an escape (see above). The result is printable UTF-8 on one line.
inline std::string terminal_safe(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (size_t i = 0; i < s.size();) {
    const uint8_t b = static_cast<uint8_t>(s[i]);
    if (b < 0x20 || b == 0x7F) {
      switch (b) {
        case '\n': out += "\\n"; break;
        case '\r': out += "\\r"; break;
        case '\t': out += "\\t"; break;
        case 0x1B: out += "\\e"; break;
        default: display_detail::hex_byte(out, b);
      }
      ++i;
      continue;
    }
    if (b < 0x80) {
      out += char(b);
      ++i;
      continue;
    }
    uint32_t cp = 0;
    const size_t n = display_detail::utf8_sequence(s, i, cp);
    if (n == 0) {
      display_detail::hex_byte(out, b);
      ++i;
      continue;
    }
    if (display_detail::invisible_control(cp)) {
      static const char* const kHex = "0123456789abcdef";
      std::string digits;
      for (uint32_t v = cp; v; v >>= 4) digits.insert(digits.begin(), kHex[v & 15]);
      out += "\\u{" + digits + "}";
    } else {
      out.append(s.substr(i, n));
    }
    i += n;
  }
  return out;
}

// At most `max` bytes of `s`, cut at a UTF-8 character boundary, "..." where cut: a
// value of megabytes is shown by its start.
inline std::string clip_text(std::string_view s, size_t max = 100) {
  if (s.size() <= max) return std::string(s);
  size_t n = max;
  while (n > 0 && (static_cast<uint8_t>(s[n]) & 0xC0) == 0x80) --n;
  return std::string(s.substr(0, n)) + "...";
}

// Markdown prose (a list item, text in a table cell): terminal_safe, then Markdown's
// punctuation that could start markup, a link, raw HTML or a new table cell
// backslash-escaped (CommonMark shows "\|" as "|").
inline std::string markdown_text(std::string_view s) {
  std::string out;
  for (char c : terminal_safe(s)) {
    if (std::string_view("\\`*_[]<>|#!~&").find(c) != std::string_view::npos) out += '\\';
    out += c;
  }
  return out;
}

// A Markdown code span for a table cell: terminal_safe, '|' escaped (GitHub's tables
// split cells on '|' even inside code), fenced by one backtick more than the longest run
// of backticks in it.
inline std::string markdown_code(std::string_view s) {
  std::string body;
  size_t run = 0, longest = 0;
  for (char c : terminal_safe(s)) {
    run = c == '`' ? run + 1 : 0;
    longest = run > longest ? run : longest;
    if (c == '|') body += '\\';
    body += c;
  }
  const std::string fence(longest + 1, '`');
  // A space on each side where the text starts or ends with a backtick (CommonMark strips one).
  const bool pad = !body.empty() && (body.front() == '`' || body.back() == '`');
  return fence + (pad ? " " : "") + body + (pad ? " " : "") + fence;
}

}  // namespace pb
