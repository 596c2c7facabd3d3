// The words and numbers of OBJ and MTL text, shared by the OBJ reader (obj_reader.cpp), its chunking for two
// threads (obj_chunks.cpp) and the MTL reader (mtl_reader.cpp): logical lines, blank-separated words, exact numbers.
#pragma once

#include <charconv>
#include <cmath>
#include <string>
#include <string_view>
#include <system_error>

namespace vox {

inline bool isObjBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

// Logical lines of a text: CR before LF dropped, a line ending in a backslash joined with the next one.
class LineReader {
 public:
  // `linesBefore`: the physical lines before `text` in its file, so that numbers count from the file's start.
  explicit LineReader(std::string_view text, long long linesBefore = 0) : text_(text), physical_(linesBefore) {}

  // The next logical line and the number of its first physical line; false at the end of the text.
  bool next(std::string_view& line, long long& number);

  // The physical lines read so far, those before the text included.
  long long physicalLines() const { return physical_; }

 private:
  std::string_view text_;
  size_t pos_ = 0;
  long long physical_ = 0;
  std::string joined_;  // a line built from continuations
};

// Whitespace-separated words of one line; a word starting with '#' ends the line.
struct Words {
  std::string_view rest;

  std::string_view next() {
    size_t i = 0;
    while (i < rest.size() && isObjBlank(rest[i])) ++i;
    rest.remove_prefix(i);
    if (rest.empty() || rest[0] == '#') {
      rest = {};
      return {};
    }
    size_t j = 0;
    while (j < rest.size() && !isObjBlank(rest[j])) ++j;
    const std::string_view word = rest.substr(0, j);
    rest.remove_prefix(j);
    return word;
  }

  // The rest of the line without surrounding blanks (a name may hold spaces).
  std::string_view name() {
    while (!rest.empty() && isObjBlank(rest.front())) rest.remove_prefix(1);
    while (!rest.empty() && isObjBlank(rest.back())) rest.remove_suffix(1);
    return rest;
  }
};

// A whole word as a finite double, rounded to nearest by std::from_chars. A leading '+' is accepted as
// strtod does; "nan", "inf", hexadecimal and out-of-range numbers are refused.
inline bool parseObjNumber(std::string_view s, double& value) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  if (s.empty() || s[0] == '+') return false;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  return ec == std::errc() && end == s.data() + s.size() && std::isfinite(value);
}

enum class IntegerStatus { Ok, Bad, TooLarge };

inline IntegerStatus parseObjInteger(std::string_view s, long long& value) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  if (s.empty() || s[0] == '+') return IntegerStatus::Bad;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (end != s.data() + s.size()) return IntegerStatus::Bad;
  if (ec == std::errc::result_out_of_range) return IntegerStatus::TooLarge;
  return ec == std::errc() ? IntegerStatus::Ok : IntegerStatus::Bad;
}

}  // namespace vox
