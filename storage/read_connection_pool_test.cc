#include "storage/read_connection_pool.h"

#include <atomic>
#include <thread>

#include "gtest/gtest.h"
#include "storage/sqlite_store.h"
#include "storage/temp_db_dir_for_test.h"

namespace surfmap {
namespace {

class ReadConnectionPoolTest : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_TRUE(SqliteStore::Open(path_).ok()); }  // creates the file
  TempDbDir dir_;
  std::string path_ = dir_.Path("surfmap.db");
};

TEST_F(ReadConnectionPoolTest, BulkLoansNeverTakeTheLastConnection) {
  ReadConnectionPool pool(path_, /*max_connections=*/3, /*max_bulk=*/2, 1000);
  auto bulk1 = pool.Borrow(ReadSize::kBulk);
  auto bulk2 = pool.Borrow(ReadSize::kBulk);
  ASSERT_TRUE(bulk1.ok() && bulk2.ok());
  // Both bulk slots are taken: a third bulk read waits, a small read does not.
  std::atomic<bool> third_bulk{false};
  std::thread waiter([&] {
    auto bulk3 = pool.Borrow(ReadSize::kBulk);
    EXPECT_TRUE(bulk3.ok());
    third_bulk = true;
  });
  auto small = pool.Borrow(ReadSize::kSmall);
  ASSERT_TRUE(small.ok()) << small.status();
  EXPECT_TRUE((*small)->QueryInt("SELECT 1").ok());
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_FALSE(third_bulk.load()) << "a third bulk loan exceeds max_bulk = 2";
  { auto release = std::move(*bulk1); }  // returns a bulk slot
  waiter.join();
  EXPECT_TRUE(third_bulk.load());
}

TEST_F(ReadConnectionPoolTest, BulkCapStaysBelowThePoolSize) {
  // max_bulk >= max_connections is clamped so one connection stays for small reads.
  ReadConnectionPool pool(path_, /*max_connections=*/2, /*max_bulk=*/5, 1000);
  auto bulk = pool.Borrow(ReadSize::kBulk);
  ASSERT_TRUE(bulk.ok());
  auto small = pool.Borrow(ReadSize::kSmall);
  ASSERT_TRUE(small.ok()) << small.status();
}

}  // namespace
}  // namespace surfmap
