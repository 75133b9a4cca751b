// Sweep files: parsed as strictly as scenes, and `base_file` confined to the
// sweep file's directory unless the caller allows more.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "absl/status/status.h"
#include "convert/sweep_file.h"

namespace cablesim {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

constexpr char kScene[] = R"({"cables": [{"name": "c", "length": 1, "density": 1000,
  "youngs_modulus": 1e7, "diameter": 0.01}], "solver": {"duration": 0.1}})";

class SweepFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() /
            ("cablesim_sweep_file_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
             "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_ / "sweeps" / "scenes");
    // Outside the sweep directory, bytes that must never be echoed.
    std::ofstream(root_ / "outside.json") << "SECRET-BYTES-not-json";
    std::ofstream(root_ / "good-outside.json") << kScene;
    std::ofstream(root_ / "sweeps" / "scenes" / "base.json") << kScene;
  }
  void TearDown() override { fs::remove_all(root_); }

  absl::StatusOr<v1::SubmitSweepRequest> Read(const std::string& body, bool allow_outside = false) {
    const std::string path = (root_ / "sweeps" / "sweep.json").string();
    std::ofstream(path) << body;
    return ReadSweepFile(path, allow_outside);
  }

  fs::path root_;
};

TEST_F(SweepFileTest, BaseFileUnderTheDirectoryIsRead) {
  const auto request = Read(R"({"base_file": "scenes/base.json",
                                "axes": [{"path": "solver.step", "values": [1e-3]}]})");
  ASSERT_TRUE(request.ok()) << request.status();
  EXPECT_EQ(request->base().cables(0).name(), "c");
  EXPECT_EQ(request->name(), "sweep");
}

TEST_F(SweepFileTest, BaseFileOutsideIsRefusedWithoutReadingIt) {
  for (const std::string& base :
       {std::string("../outside.json"), (root_ / "outside.json").string(),
        std::string("scenes/../../outside.json")}) {
    const auto request = Read(R"({"base_file": ")" + base + R"("})");
    ASSERT_FALSE(request.ok()) << base;
    EXPECT_EQ(request.status().code(), absl::StatusCode::kInvalidArgument);
    const std::string message(request.status().message());
    EXPECT_THAT(message, HasSubstr("base_file: must be under the sweep file's directory"));
    EXPECT_THAT(message, HasSubstr("--allow-outside"));
    EXPECT_THAT(message, Not(HasSubstr("SECRET")));
  }
}

TEST_F(SweepFileTest, ASymbolicLinkLeadingOutsideIsRefused) {
  fs::create_symlink(root_ / "good-outside.json", root_ / "sweeps" / "link.json");
  const auto request = Read(R"({"base_file": "link.json"})");
  ASSERT_FALSE(request.ok());
  EXPECT_THAT(std::string(request.status().message()), HasSubstr("must be under"));
}

TEST_F(SweepFileTest, AllowOutsideReadsAnyFileAndStillQuotesNoRawBytes) {
  const auto good = Read(R"({"base_file": "../good-outside.json"})", true);
  ASSERT_TRUE(good.ok()) << good.status();
  EXPECT_EQ(good->base().cables_size(), 1);
  const auto bad = Read(R"({"base_file": "../outside.json"})", true);
  ASSERT_FALSE(bad.ok());
  EXPECT_THAT(std::string(bad.status().message()), HasSubstr("base_file: "));
}

TEST_F(SweepFileTest, ValuesOfTheWrongKindAreNamed) {
  const auto request = Read(R"({"base_file": "scenes/base.json", "axes": {"path": "solver.step"}})");
  ASSERT_FALSE(request.ok());
  EXPECT_THAT(std::string(request.status().message()),
              HasSubstr("axes: must be a list [...] (got an object)"));
}

}  // namespace
}  // namespace cablesim
