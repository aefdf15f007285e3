#pragma once
// No partial files: outputs are written under a temporary name in their own folder and renamed
// into place only when complete. An AtomicOutput that is never committed removes its temporary.
#include <filesystem>

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

// Throws naris::Error unless `folder` exists (or can be created) and accepts new files.
void ensure_writable_folder(const std::filesystem::path& folder);

}  // namespace naris
