// What the simulator's plain-text inputs share (path scripts, path_script.h;
// map changes, map_changes.h): one command a line, '#' starts a comment, and
// a malformed line is reported as "file:line: message".
#pragma once

#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace pf::sim {

/// The whitespace-separated words of `text` before its first '#'.
inline std::vector<std::string> scriptWords(const std::string& text) {
  std::istringstream in(text.substr(0, text.find('#')));
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

/// One line's words (command first); every failure throws
/// Error("file:line: message").
template <typename Error>
class LineParser {
 public:
  LineParser(const std::string& file, int line, std::vector<std::string> words)
      : file_(file), line_(line), words_(std::move(words)) {}

  [[noreturn]] void fail(const std::string& message) const {
    throw Error(file_ + ":" + std::to_string(line_) + ": " + message);
  }

  const std::string& command() const { return words_[0]; }

  /// The arguments as finite numbers; exactly `count` of them, named in `usage`.
  std::vector<double> numbers(std::size_t count, const std::string& usage) const {
    if (words_.size() != count + 1) {
      fail("'" + command() + "' takes " + std::to_string(count) + " number(s): " + usage);
    }
    std::vector<double> out;
    for (std::size_t i = 1; i < words_.size(); ++i) {
      const char* begin = words_[i].c_str();
      char* end = nullptr;
      const double value = std::strtod(begin, &end);
      if (end == begin || *end != '\0' || !std::isfinite(value)) {
        fail("'" + words_[i] + "' is not a number (in '" + command() + "')");
      }
      out.push_back(value);
    }
    return out;
  }

  /// The one word after the command, as `usage` names it.
  const std::string& word(const std::string& usage) const {
    if (words_.size() != 2) fail("expected '" + usage + "'");
    return words_[1];
  }

  void requirePositive(double value, const std::string& what) const {
    if (!(value > 0.0)) fail(what + " must be positive, got " + std::to_string(value));
  }

 private:
  const std::string& file_;
  int line_;
  std::vector<std::string> words_;
};

}  // namespace pf::sim
