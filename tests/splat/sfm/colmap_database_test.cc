#include "splat/sfm/colmap_database.h"

#include <gtest/gtest.h>
#include <sqlite3.h>

#include "splat/error.h"
#include "tests/test_util.h"

namespace splat {
namespace {

// A database with COLMAP's images table, as feature_extractor creates it.
void make_database(const std::filesystem::path& file, const std::string& inserts) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  const std::string sql =
      "CREATE TABLE images (image_id INTEGER PRIMARY KEY AUTOINCREMENT NOT NULL, name TEXT NOT "
      "NULL UNIQUE, camera_id INTEGER NOT NULL, prior_qw REAL, prior_qx REAL, prior_qy REAL, "
      "prior_qz REAL, prior_tx REAL, prior_ty REAL, prior_tz REAL);" +
      inserts;
  char* error = nullptr;
  EXPECT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error), SQLITE_OK)
      << (error ? error : "");
  sqlite3_free(error);
  sqlite3_close(db);
}

TEST(ColmapDatabase, ReadsTheIdsColmapGaveEachImage) {
  const testing_util::TempDir tmp;
  make_database(tmp / "database.db",
                "INSERT INTO images (image_id, name, camera_id) VALUES (7, 'b.jpg', 1);"
                "INSERT INTO images (image_id, name, camera_id) VALUES (3, 'sub/a.png', 2);");
  const auto images = read_database_images(tmp / "database.db");
  ASSERT_EQ(images.size(), 2u);
  EXPECT_EQ(images.at("b.jpg").image_id, 7u);
  EXPECT_EQ(images.at("b.jpg").camera_id, 1u);
  EXPECT_EQ(images.at("sub/a.png").image_id, 3u);
  EXPECT_EQ(images.at("sub/a.png").camera_id, 2u);
}

TEST(ColmapDatabase, CountsTheVerifiedMatchesOfEveryPair) {
  const testing_util::TempDir tmp;
  const std::string table =
      "CREATE TABLE two_view_geometries (pair_id INTEGER PRIMARY KEY NOT NULL, rows INTEGER NOT "
      "NULL, cols INTEGER NOT NULL, data BLOB, config INTEGER NOT NULL);";
  make_database(tmp / "none.db", table);
  EXPECT_EQ(count_verified_matches(tmp / "none.db"), 0u);
  make_database(tmp / "some.db", table +
                                     "INSERT INTO two_view_geometries VALUES (1, 30, 2, NULL, 2);"
                                     "INSERT INTO two_view_geometries VALUES (2, 12, 2, NULL, 2);");
  EXPECT_EQ(count_verified_matches(tmp / "some.db"), 42u);
  make_database(tmp / "images_only.db", "");
  EXPECT_THROW(count_verified_matches(tmp / "images_only.db"), InputError);
}

TEST(ColmapDatabase, AMissingOrForeignFileNamesIt) {
  const testing_util::TempDir tmp;
  for (const auto& file : {tmp / "absent.db", tmp / "garbage.db"}) {
    if (file.filename() == "garbage.db") testing_util::write_file(file, "not a database at all");
    try {
      read_database_images(file);
      FAIL() << "expected InputError for " << file;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(file.filename().string()), std::string::npos)
          << e.what();
    }
  }
}

}  // namespace
}  // namespace splat
