#include "splat/sfm/colmap_database.h"

#include <sqlite3.h>

#include <memory>

#include "splat/error.h"

namespace splat {

std::map<std::string, DatabaseImage> read_database_images(const std::filesystem::path& file) {
  sqlite3* raw = nullptr;
  if (sqlite3_open_v2(file.c_str(), &raw, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    sqlite3_close(raw);
    throw InputError(file, "cannot open the COLMAP database");
  }
  const std::unique_ptr<sqlite3, decltype(&sqlite3_close)> db(raw, sqlite3_close);
  sqlite3_stmt* stmt = nullptr;
  if (sqlite3_prepare_v2(db.get(), "SELECT image_id, camera_id, name FROM images", -1, &stmt,
                         nullptr) != SQLITE_OK)
    throw InputError(file, std::string("not a COLMAP database: ") + sqlite3_errmsg(db.get()));
  std::map<std::string, DatabaseImage> images;
  while (sqlite3_step(stmt) == SQLITE_ROW) {
    const auto* name = reinterpret_cast<const char*>(sqlite3_column_text(stmt, 2));
    images[name ? name : ""] = {uint32_t(sqlite3_column_int64(stmt, 0)),
                                uint32_t(sqlite3_column_int64(stmt, 1))};
  }
  sqlite3_finalize(stmt);
  return images;
}

}  // namespace splat
