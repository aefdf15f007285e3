#pragma once
// Lists given as text on the command line and in case files.
#include <string>
#include <vector>

namespace naris {

// The items of "a,b,c" split at each separator, empty items kept ("a,,b" has three; "" one).
inline std::vector<std::string> split_list(const std::string& text, char separator = ',') {
  std::vector<std::string> items;
  std::size_t start = 0;
  while (true) {
    const std::size_t end = text.find(separator, start);
    items.push_back(text.substr(start, end == std::string::npos ? std::string::npos : end - start));
    if (end == std::string::npos) return items;
    start = end + 1;
  }
}

}  // namespace naris
