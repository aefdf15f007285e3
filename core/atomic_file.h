#pragma once
// No partial files: outputs are written under a temporary name in their own folder and renamed
// into place only when complete. An AtomicOutput that is never committed removes its temporary.
#include <filesystem>
#include <string_view>

namespace naris {

class AtomicOutput {
 public:
  explicit AtomicOutput(std::filesystem::path target);
  ~AtomicOutput();
  AtomicOutput(const AtomicOutput&) = delete;
  AtomicOutput& operator=(const AtomicOutput&) = delete;

  const std::filesystem::path& temp_path() const { return temp_; }
  const std::filesystem::path& target() const { return target_; }
  void commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path temp_;
  bool committed_ = false;
};

// Writes `text` as the whole of `path` through an AtomicOutput; throws naris::Error when the
// write fails (the old file, if any, stays).
void write_text_file(const std::filesystem::path& path, std::string_view text);

// Throws naris::Error unless `folder` exists (or can be created) and accepts new files.
void ensure_writable_folder(const std::filesystem::path& folder);

}  // namespace naris
