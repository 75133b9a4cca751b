#ifndef CABLESIM_TESTS_BOTH_STORES_TEST_UTIL_H_
#define CABLESIM_TESTS_BOTH_STORES_TEST_UTIL_H_

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "postgres_test_util.h"

namespace cablesim::testing {

// A cablesim-server test run against either store (the parameter,
// "sqlite" or "postgresql"): StoreFlags gives the server's flags for a
// fresh store, none for SQLite (the data directory), --store=URL for a
// fresh PostgreSQL database; `skipped_` when PostgreSQL is not installed
// (then GTEST_SKIP), a failure when it is but cannot start.
class BothStoresTest : public ::testing::TestWithParam<std::string> {
 protected:
  std::vector<std::string> StoreFlags(const std::string& name) {
    if (GetParam() == "sqlite") return {};
    std::string why;
    TestPostgres* pg = TestPostgres::Get(&why);
    if (pg == nullptr) {
      if (TestPostgres::NotInstalled(why)) {
        skipped_ = true;
        return {};
      }
      ADD_FAILURE() << "PostgreSQL is installed but cannot start: " << why;
      return {};
    }
    return {"--store=" + pg->NewDatabase(name)};
  }
  bool skipped_ = false;
};

}  // namespace cablesim::testing

#endif  // CABLESIM_TESTS_BOTH_STORES_TEST_UTIL_H_
