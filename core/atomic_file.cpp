#include "core/atomic_file.h"

#include <unistd.h>

#include <fstream>
#include <system_error>

#include "core/error.h"

namespace naris {
namespace fs = std::filesystem;

AtomicOutput::AtomicOutput(fs::path target) : target_(std::move(target)) {
  temp_ = target_;
  temp_ += ".part-" + std::to_string(::getpid());
}

AtomicOutput::~AtomicOutput() {
  if (!committed_) {
    std::error_code ec;
    fs::remove(temp_, ec);
  }
}

void AtomicOutput::commit() {
  std::error_code ec;
  fs::rename(temp_, target_, ec);
  if (ec) fail("{}: cannot move the finished file into place: {}", target_.string(), ec.message());
  committed_ = true;
}

void write_text_file(const fs::path& path, std::string_view text) {
  AtomicOutput out(path);
  {
    std::ofstream f(out.temp_path(), std::ios::binary);
    f.write(text.data(), static_cast<std::streamsize>(text.size()));
    f.flush();
    if (!f) fail("{}: write failed (disk full?)", path.string());
  }
  out.commit();
}

void ensure_writable_folder(const fs::path& folder) {
  const fs::path dir = folder.empty() ? fs::path(".") : folder;
  std::error_code ec;
  if (!fs::exists(dir, ec)) {
    fs::create_directories(dir, ec);
    if (ec) fail("{}: cannot create the output folder: {}", dir.string(), ec.message());
  }
  if (!fs::is_directory(dir, ec)) fail("{}: the output path is not a folder", dir.string());
  if (::access(dir.c_str(), W_OK) != 0)
    fail("{}: the output folder is not writable (check its permissions or choose another -o)",
         dir.string());
}

}  // namespace naris
