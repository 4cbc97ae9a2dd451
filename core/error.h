// User errors carry the place in the input that caused them (file, line,
// column), the key, and a suggestion; the command line maps them to exit 2.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

namespace morphoflow {

struct SourceLocation {
  std::string file;
  int line = 0;    // 1-based; 0 when unknown
  int column = 0;  // 1-based; 0 when unknown
};

class UserError : public std::runtime_error {
 public:
  UserError(SourceLocation where, std::string key, std::string message, std::string hint = {})
      : std::runtime_error(format(where, key, message, hint)),
        where_(std::move(where)),
        key_(std::move(key)),
        message_(std::move(message)),
        hint_(std::move(hint)) {}
  const SourceLocation& where() const { return where_; }
  const std::string& key() const { return key_; }
  const std::string& message() const { return message_; }
  const std::string& hint() const { return hint_; }

 private:
  static std::string format(const SourceLocation& w, const std::string& key, const std::string& msg,
                            const std::string& hint) {
    std::ostringstream s;
    s << w.file;
    if (w.line > 0) s << ':' << w.line << ':' << w.column;
    s << ": error: ";
    if (!key.empty()) s << '\'' << key << "': ";
    s << msg;
    if (!hint.empty()) s << " (" << hint << ')';
    return s.str();
  }
  SourceLocation where_;
  std::string key_, message_, hint_;
};

// A field turned NaN, infinite or too large for a float: the run stops
// (exit 2) with the step, the stage and what to change.
// A run stopped because it diverged (a NonFiniteError met by the run loop),
// reported as a UserError (exit 2) with the run's location; Python raises
// FloatingPointError for it, as for a diverging step.
class DivergedError : public UserError {
 public:
  using UserError::UserError;
};

class NonFiniteError : public std::runtime_error {
 public:
  NonFiniteError(const std::string& message, std::string hint) : std::runtime_error(message), hint_(std::move(hint)) {}
  const std::string& hint() const { return hint_; }

 private:
  std::string hint_;
};

}  // namespace morphoflow
