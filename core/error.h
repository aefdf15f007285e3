#pragma once
// The one exception type of naris: its message is written for a person and says what went
// wrong, where, and what to do. The command line prints it as `naris: error: <message>`.
#include <fmt/format.h>

#include <stdexcept>
#include <string>

namespace naris {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

template <class... Args>
[[noreturn]] void fail(fmt::format_string<Args...> format, Args&&... args) {
  throw Error(fmt::format(format, std::forward<Args>(args)...));
}

}  // namespace naris
