#pragma once
// Progress and timing for long loops. Logs go to stderr; data goes to files. A progress bar is
// drawn only on a terminal and only for work that lasts longer than a moment.
#include <chrono>
#include <cstddef>
#include <string>

namespace naris {

enum class Verbosity { quiet, normal };

void set_verbosity(Verbosity v);
Verbosity verbosity();

// Prints a line to stderr unless quiet.
void log_line(const std::string& line);

// Peak resident set size of this process in bytes (VmHWM).
std::size_t peak_memory_bytes();

class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

// A terminal progress bar, throttled to a few updates a second and shown only after ~1 s.
class Progress {
 public:
  Progress(std::string label, std::size_t total);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  void update(std::size_t done);
  void finish();

 private:
  std::string label_;
  std::size_t total_;
  Stopwatch clock_;
  double last_draw_ = -1.0;
  bool drawn_ = false;
  bool active_;
};

}  // namespace naris
