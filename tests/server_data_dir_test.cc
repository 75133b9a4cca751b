// The data directory on a first start: a missing one is created private
// (0700) and the server serves; one that cannot be created ends the start
// with a message naming it (exit 1). The CI recipe of docs/tutorials/sweep-in-ci.md, run as
// written, ends at once with the server's status and message instead of
// waiting for a port file that never comes.

#include <sys/stat.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "tests/server_test_util.h"

namespace cablesim {
namespace {

using ::cablesim::testing::FreshDir;
using ::cablesim::testing::ServerProcess;
using ::testing::HasSubstr;

std::string ReadAll(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

TEST(ServerDataDirTest, AMissingDataDirectoryIsCreatedPrivate) {
  const std::string root = FreshDir("data_dir_missing");
  const std::string dir = root + "/not/yet/there";
  // The port file and the log live beside the data directory, which the
  // server must create itself.
  const std::string port_file = root + "/port", log = root + "/server.log";
  const int status = std::system(
      absl::StrCat("'", CABLESIM_BIN_DIR, "/cablesim-server' --listen=127.0.0.1:0 --data-dir='",
                   dir, "' --port-file='", port_file, "' 2>'", log,
                   "' & pid=$!; for i in $(seq 600); do [ -s '", port_file,
                   "' ] && break; kill -0 $pid 2>/dev/null || break; sleep 0.1; done; "
                   "kill -TERM $pid; wait $pid")
          .c_str());
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status << "\n" << ReadAll(log);
  EXPECT_FALSE(ReadAll(port_file).empty()) << ReadAll(log);
  struct stat st;
  ASSERT_EQ(::stat(dir.c_str(), &st), 0);
  EXPECT_TRUE(S_ISDIR(st.st_mode));
  EXPECT_EQ(st.st_mode & 0777, 0700u);
  EXPECT_TRUE(std::filesystem::exists(dir + "/cablesim.db"));
}

TEST(ServerDataDirTest, ADirectoryThatCannotBeCreatedIsNamed) {
  const std::string root = FreshDir("data_dir_blocked");
  std::ofstream(root + "/a-file") << "not a directory\n";
  std::string log;
  const std::string dir = root + "/a-file/jobs";
  // StartRefused writes its log into the data directory, which cannot
  // exist here: run the server directly.
  const int status =
      std::system(absl::StrCat("timeout 60 '", CABLESIM_BIN_DIR,
                               "/cablesim-server' --listen=127.0.0.1:0 --data-dir='", dir,
                               "' 2>'", root, "/refused.log'")
                      .c_str());
  log = ReadAll(root + "/refused.log");
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1) << log;
  EXPECT_THAT(log, HasSubstr(absl::StrCat("cannot create the data directory ", dir,
                                          ": Not a directory")));
}

// The store flag: --store sqlite:DIR is --data-dir DIR; one of the two,
// and a store of a kind the server knows, or a usage error (exit 2); a
// database that cannot be reached ends the start (exit 1), named without
// its password.
TEST(ServerDataDirTest, TheStoreFlagTakesSqliteOrPostgresql) {
  const std::string root = FreshDir("store_flag");
  auto start = [&](const std::string& flags, std::string* log) {
    const int status = std::system(absl::StrCat("timeout 60 '", CABLESIM_BIN_DIR,
                                                "/cablesim-server' --listen=127.0.0.1:0 ", flags,
                                                " 2>'", root, "/log'")
                                       .c_str());
    *log = ReadAll(root + "/log");
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  std::string log;
  EXPECT_EQ(start("", &log), 2);
  EXPECT_THAT(log, HasSubstr("give one of --data-dir DIR and --store"));
  EXPECT_EQ(start(absl::StrCat("--data-dir=", root, "/a --store=sqlite:", root, "/b"), &log), 2);
  EXPECT_EQ(start("--store=mysql://db/jobs", &log), 2);
  EXPECT_THAT(log, HasSubstr("expected sqlite:DIR or postgresql://"));
  EXPECT_EQ(start("--store=postgresql://cablesim:s3cret@127.0.0.1:1/jobs?connect_timeout=5", &log),
            1);
  EXPECT_THAT(log, HasSubstr("cannot connect to the PostgreSQL job store"));
  EXPECT_THAT(log, ::testing::Not(HasSubstr("s3cret")));

  // sqlite:DIR serves, and creates DIR as --data-dir does.
  const std::string dir = root + "/sqlite-store";
  ServerProcess server(root, {"--store=sqlite:" + dir});
  ASSERT_GT(server.port(), 0);
  EXPECT_TRUE(server.WaitForLog("jobs in sqlite:" + dir));
  EXPECT_TRUE(std::filesystem::exists(dir + "/cablesim.db"));
}

// The block of docs/tutorials/sweep-in-ci.md that follows "A CI job against a daemon".
std::string ReadmeCiRecipe() {
  const std::string readme = ReadAll(absl::StrCat(CABLESIM_SOURCE_DIR, "/docs/tutorials/sweep-in-ci.md"));
  const size_t intro = readme.find("A CI job against a daemon");
  const size_t start = readme.find("```sh\n", intro);
  const size_t end = readme.find("```\n", start + 6);
  if (intro == std::string::npos || start == std::string::npos || end == std::string::npos) {
    return "";
  }
  return readme.substr(start + 6, end - start - 6);
}

TEST(ServerDataDirTest, TheReadmeCiRecipeFailsFastWhenTheServerCannotStart) {
  std::string recipe = ReadmeCiRecipe();
  ASSERT_THAT(recipe, HasSubstr("--data-dir ci-jobs")) << recipe;
  const std::string root = FreshDir("data_dir_recipe");
  std::ofstream(root + "/a-file") << "not a directory\n";
  // Run from a scratch directory with the binaries of this build; the data
  // directory is one the server cannot create.
  recipe = absl::StrReplaceAll(recipe, {{"build/bin/", absl::StrCat(CABLESIM_BIN_DIR, "/")},
                                        {"--data-dir ci-jobs", "--data-dir a-file/ci-jobs"}});
  std::ofstream(root + "/recipe.sh") << recipe;
  const auto started = std::chrono::steady_clock::now();
  const int status = std::system(
      absl::StrCat("cd '", root, "' && timeout 60 bash recipe.sh 2> recipe.log").c_str());
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  const std::string log = ReadAll(root + "/recipe.log");
  ASSERT_TRUE(WIFEXITED(status));
  // 124 would be timeout's: the recipe waited for the port file.
  EXPECT_EQ(WEXITSTATUS(status), 1) << log;
  EXPECT_THAT(log, HasSubstr("cablesim-server: cannot create the data directory a-file/ci-jobs"));
  // The server refuses within milliseconds; 10 s is far from both that
  // and the 60 s of a recipe that waits.
  EXPECT_LT(seconds, 10.0);
}

}  // namespace
}  // namespace cablesim
