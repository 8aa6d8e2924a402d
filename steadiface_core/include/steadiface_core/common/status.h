#pragma once

#include <string>
#include <utility>

namespace steadiface {

/// A success flag with a human-readable message. The core never exits or
/// aborts on bad input or options: it returns one of these instead, and a
/// caller that drops one gets a warning ([[nodiscard]]).
class [[nodiscard]] Status {
 public:
  Status() = default;
  static Status Ok() { return Status(); }
  static Status Error(std::string message) {
    Status s;
    s.ok_ = false;
    s.message_ = std::move(message);
    return s;
  }

  bool ok() const { return ok_; }
  const std::string& message() const { return message_; }
  explicit operator bool() const { return ok_; }

 private:
  bool ok_ = true;
  std::string message_;
};

}  // namespace steadiface
