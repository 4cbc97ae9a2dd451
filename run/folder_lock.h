// FolderLock: an advisory lock (flock) on an output folder for the life of
// the run or batch that writes it, so that a second process into the same
// folder is refused (exit 2 naming the holder's pid) before it deletes or
// interleaves anything. The lock is the kernel's: it goes with the process,
// however it ends. A filesystem without locks (some network mounts) runs
// unlocked.
#pragma once

#include <filesystem>
#include <string>

namespace morphoflow {

class FolderLock {
 public:
  // Locks `folder` (which exists) under the name `name` (the lock file,
  // `.morphoflow.lock` by default; a batch's shards each take their own);
  // throws UserError when another process holds it.
  explicit FolderLock(const std::filesystem::path& folder, const std::string& name = ".morphoflow.lock");
  ~FolderLock();
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

 private:
  int fd_ = -1;
};

// The environment variable through which a batch tells its children its pid:
// a child whose batch is gone stops (SIGTERM: it checkpoints and exits 143).
inline constexpr const char* kBatchParentVariable = "MORPHOFLOW_BATCH_PARENT";
// In a child of a batch: asks for SIGTERM when the batch dies, and stops at
// once if it is already gone.
void stopWithBatchParent();

}  // namespace morphoflow
