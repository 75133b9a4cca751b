// The README and docs/ are read by users who have only this repository:
// every file they link or name by path must exist in it.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace cablesim {
namespace {

namespace fs = std::filesystem;

std::string Read(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Files named in `doc` (relative to `base`) that do not exist: markdown link
// targets other than URLs, and `code` spans that look like a repository path
// (a '/', a file extension; build outputs excepted).
std::vector<std::string> MissingFiles(const fs::path& doc, const fs::path& base) {
  const std::string text = Read(doc);
  std::vector<std::string> missing;
  static const std::regex link(R"(\]\(([^)#\s]+)\))");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), link); it != std::sregex_iterator();
       ++it) {
    const std::string target = (*it)[1];
    if (target.rfind("http", 0) == 0) continue;
    if (!fs::exists(doc.parent_path() / target)) missing.push_back(target);
  }
  static const std::regex code(R"(`([A-Za-z0-9_./-]+/[A-Za-z0-9_.-]+\.(md|h|cc|json|proto|py|sh|in))`)");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), code); it != std::sregex_iterator();
       ++it) {
    const std::string path = (*it)[1];
    if (path.rfind("build/", 0) == 0) continue;
    if (!fs::exists(base / path)) missing.push_back(path);
  }
  if (text.find("../shared") != std::string::npos) missing.push_back("../shared (outside)");
  return missing;
}

TEST(ReadmeLinksTest, TheReadmeNamesOnlyFilesOfTheRepository) {
  const fs::path root = CABLESIM_SOURCE_DIR;
  EXPECT_THAT(MissingFiles(root / "README.md", root), ::testing::IsEmpty());
}

// Every page under docs/ (the MkDocs site; symbolic links such as
// docs/bench-results are not followed: their files are checked where they
// live).
TEST(ReadmeLinksTest, TheDocsNameOnlyFilesOfTheRepository) {
  const fs::path root = CABLESIM_SOURCE_DIR;
  ASSERT_TRUE(fs::exists(root / "docs" / "model.md"));
  int pages = 0;
  for (const auto& entry : fs::recursive_directory_iterator(root / "docs")) {
    if (entry.path().extension() != ".md") continue;
    ++pages;
    EXPECT_THAT(MissingFiles(entry.path(), root), ::testing::IsEmpty()) << entry.path();
  }
  EXPECT_GE(pages, 20) << "docs/tutorials/, docs/reference/, docs/features/ not found";
}

// The README is read in minutes: under 150 lines, opening with the two
// commands (the sample built and run; every test), the second exactly the
// one .ci/run runs.
TEST(ReadmeLinksTest, TheReadmeIsShortAndStartsWithTheTwoCommands) {
  const fs::path root = CABLESIM_SOURCE_DIR;
  const std::string readme = Read(root / "README.md");
  const auto lines = std::count(readme.begin(), readme.end(), '\n');
  EXPECT_LT(lines, 150);
  const std::string head =
      "# cablesim\n\n```sh\n"
      "deploy/install-deps.sh && cmake -S . -B build && cmake --build build -j2 --target cablesim "
      "&& build/bin/cablesim run scenes/falling-pendulum.json --out falling-pendulum.csv\n"
      "cmake -S . -B build && cmake --build build -j2 && ctest --test-dir build -j2 "
      "--output-on-failure\n```\n";
  EXPECT_EQ(readme.substr(0, head.size()), head);
}

}  // namespace
}  // namespace cablesim
