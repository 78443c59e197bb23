// Where a test puts its campaign: an SQLite file in the test's folder, or a new database on the
// test process's throwaway PostgreSQL server (tests/common/postgres_server.h) with the files root
// in the test's folder. The queue tests run on both (parameterised by Store).
#pragma once
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tests/common/postgres_server.h"
#include "tests/common/temp_dir.h"

namespace gravsweep::test {

enum class Store { sqlite, postgres };

inline std::string store_name(Store s) { return s == Store::sqlite ? "sqlite" : "postgres"; }

struct CampaignStore {
  std::string location;         ///< --db: the SQLite file, or the PostgreSQL URL
  std::filesystem::path files;  ///< --files: empty for SQLite (beside the file)
  std::string skip;             ///< non-empty: why this backend cannot run here (for GTEST_SKIP)

  CampaignStore(Store s, const std::filesystem::path& dir, const std::string& stem = "c") {
    if (s == Store::sqlite) {
      location = (dir / (stem + ".db")).string();
      return;
    }
    PostgresServer* server = PostgresServer::shared(skip);
    if (!server) {
      location = ":memory:";  // never used: the test skips
      return;
    }
    location = server->create_database();
    files = dir / (stem + ".files");
  }
  /// The file of a path stored in the campaign (relative to the files root).
  [[nodiscard]] std::filesystem::path root() const {
    return files.empty() ? std::filesystem::path(location).parent_path() /
                               (std::filesystem::path(location).stem().string() + ".files")
                         : files;
  }
  /// --db LOCATION [--files DIR], for the CLI.
  [[nodiscard]] std::vector<std::string> args() const {
    std::vector<std::string> a{"--db", location};
    if (!files.empty()) a.insert(a.end(), {"--files", files.string()});
    return a;
  }
};

/// A test on the store of its parameter: a fresh folder and a campaign location in it; skipped,
/// saying why, where that backend cannot run here.
struct StoreTest : ::testing::TestWithParam<Store> {
  TempDir dir;
  CampaignStore store{GetParam(), dir.path};
  void SetUp() override {
    if (!store.skip.empty()) GTEST_SKIP() << "PostgreSQL not available: " << store.skip;
  }
};

}  // namespace gravsweep::test

/// Instantiates the parameterised suite `suite` (a TEST_P on a Store) on the backend this test
/// binary tests the queue on: PostgreSQL where it is built with GRAVSWEEP_QUEUE_TESTS_ON_POSTGRES,
/// SQLite elsewhere; each test's name carries the backend's.
#ifdef GRAVSWEEP_QUEUE_TESTS_ON_POSTGRES
#define GRAVSWEEP_INSTANTIATE_ON_THE_QUEUE_BACKEND(suite)                                          \
  INSTANTIATE_TEST_SUITE_P(Postgres, suite, ::testing::Values(::gravsweep::test::Store::postgres), \
                           [](const auto& info) { return ::gravsweep::test::store_name(info.param); })
#else
#define GRAVSWEEP_INSTANTIATE_ON_THE_QUEUE_BACKEND(suite)                                      \
  INSTANTIATE_TEST_SUITE_P(Sqlite, suite, ::testing::Values(::gravsweep::test::Store::sqlite), \
                           [](const auto& info) { return ::gravsweep::test::store_name(info.param); })
#endif
