#ifndef CABLESIM_TESTS_SCRATCH_DIR_H_
#define CABLESIM_TESTS_SCRATCH_DIR_H_

// Scratch files and directories under the test's temporary directory
// (::testing::TempDir(), /tmp unless TEST_TMPDIR says otherwise), removed
// when the test program exits having passed. A failed run keeps them, with
// the servers' logs and databases, to look at. Without this every run left
// its directories behind (thousands after a day of repeated runs).

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

namespace cablesim::testing {

namespace scratch_internal {

struct Registry {
  pid_t owner = ::getpid();
  std::vector<std::string> paths;
};

// Never destroyed: the exit handler below reads it after static
// destructors may have run.
inline Registry& TheRegistry() {
  static Registry* const registry = new Registry;
  return *registry;
}

inline void RemoveIfPassed() {
  Registry& r = TheRegistry();
  // A forked child that exits (a death test's) must not remove what its
  // parent is still using.
  if (::getpid() != r.owner) return;
  if (!::testing::UnitTest::GetInstance()->Passed()) return;
  for (const std::string& path : r.paths) {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
}

}  // namespace scratch_internal

// Registers `path` (a file or a directory, existing or not yet) for removal
// at exit if every test passed; returns it.
inline std::string Scratch(std::string path) {
  static const bool registered = (std::atexit(&scratch_internal::RemoveIfPassed), true);
  (void)registered;
  scratch_internal::TheRegistry().paths.push_back(path);
  return path;
}

// A fresh empty directory TempDir()/STEM_PID (STEM_PID: this process's),
// removed at exit like Scratch.
inline std::string ScratchDir(const std::string& stem) {
  const std::string dir =
      Scratch(::testing::TempDir() + "/" + stem + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace cablesim::testing

#endif  // CABLESIM_TESTS_SCRATCH_DIR_H_
