#include "core/log.h"

#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>

namespace naris {
namespace {
Verbosity g_verbosity = Verbosity::normal;
}

void set_verbosity(Verbosity v) {
  g_verbosity = v;
}
Verbosity verbosity() {
  return g_verbosity;
}

void log_line(const std::string& line) {
  if (g_verbosity == Verbosity::quiet) return;
  std::fprintf(stderr, "%s\n", line.c_str());
}

std::size_t peak_memory_bytes() {
  std::ifstream status("/proc/self/status");
  std::string key;
  while (status >> key) {
    if (key == "VmHWM:") {
      std::size_t kib = 0;
      status >> kib;
      return kib * 1024;
    }
    std::string rest;
    std::getline(status, rest);
  }
  return 0;
}

Progress::Progress(std::string label, std::size_t total)
    : label_(std::move(label)),
      total_(total),
      active_(g_verbosity != Verbosity::quiet && isatty(STDERR_FILENO)) {}

Progress::~Progress() {
  finish();
}

void Progress::update(std::size_t done) {
  if (!active_) return;
  const double now = clock_.seconds();
  if (now < 1.0 || now - last_draw_ < 0.25) return;
  last_draw_ = now;
  drawn_ = true;
  const double fraction = total_ ? static_cast<double>(done) / static_cast<double>(total_) : 1.0;
  const int width = 30;
  const int filled = static_cast<int>(fraction * width);
  std::fprintf(stderr, "\r%s [%.*s%*s] %3.0f%% %.1fs", label_.c_str(), filled,
               "==============================", width - filled, "", 100.0 * fraction, now);
  std::fflush(stderr);
}

void Progress::finish() {
  if (active_ && drawn_) {
    std::fprintf(stderr, "\r\033[K");
    std::fflush(stderr);
  }
  drawn_ = false;
}

}  // namespace naris
