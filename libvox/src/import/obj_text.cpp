// Logical lines of OBJ and MTL text (obj_text.h), and reading such a text file whole.
#include "import/obj_text.h"

#include <string>

#include "import/obj_reader.h"
#include "vox/core/error.h"
#include "vox/core/quote_input.h"
#include "vox/io/input_file.h"

namespace vox {

bool LineReader::next(std::string_view& line, long long& number) {
  if (pos_ >= text_.size()) return false;
  number = physical_ + 1;
  joined_.clear();
  bool joining = false;
  for (;;) {
    size_t eol = text_.find('\n', pos_);
    if (eol == std::string_view::npos) eol = text_.size();
    std::string_view piece = text_.substr(pos_, eol - pos_);
    pos_ = eol + 1;
    ++physical_;
    if (!piece.empty() && piece.back() == '\r') piece.remove_suffix(1);
    const bool continues = !piece.empty() && piece.back() == '\\';
    if (continues) piece.remove_suffix(1);
    if (!continues && !joining) {
      line = piece;
      return true;
    }
    joined_.append(piece);
    joined_ += ' ';
    joining = true;
    if (!continues || pos_ >= text_.size()) break;
  }
  line = joined_;
  return true;
}

std::string quotedWord(std::string_view word) {
  std::string out(1, '\'');
  out += quoteInput(std::string(word));
  out += '\'';
  return out;
}

HugeBuffer readTextFile(const std::string& path, const char* what, size_t maxBytes, ImportProgress* progress) {
  // Regular files only, within the limit and the memory budget.
  if (!progress) return readInputBytes(path, what, maxBytes);
  return readInputBytes(path, what, maxBytes, [&](double f) { return progress->report(0.1 * f); });
}

}  // namespace vox
