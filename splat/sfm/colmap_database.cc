#include "splat/sfm/colmap_database.h"

#include <sqlite3.h>

#include <memory>

#include "splat/error.h"

namespace splat {

namespace {

using Database = std::unique_ptr<sqlite3, decltype(&sqlite3_close)>;

Database open_database(const std::filesystem::path& file) {
  sqlite3* raw = nullptr;
  if (sqlite3_open_v2(file.c_str(), &raw, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    sqlite3_close(raw);
    throw InputError(file, "cannot open the COLMAP database");
  }
  return Database(raw, sqlite3_close);
}

sqlite3_stmt* prepare(const Database& db, const char* sql, const std::filesystem::path& file) {
  sqlite3_stmt* stmt = nullptr;
  if (sqlite3_prepare_v2(db.get(), sql, -1, &stmt, nullptr) != SQLITE_OK)
    throw InputError(file, std::string("not a COLMAP database: ") + sqlite3_errmsg(db.get()));
  return stmt;
}

}  // namespace

uint64_t count_verified_matches(const std::filesystem::path& file) {
  const Database db = open_database(file);
  sqlite3_stmt* stmt = prepare(db, "SELECT COALESCE(SUM(rows), 0) FROM two_view_geometries", file);
  const uint64_t n = sqlite3_step(stmt) == SQLITE_ROW ? uint64_t(sqlite3_column_int64(stmt, 0)) : 0;
  sqlite3_finalize(stmt);
  return n;
}

std::map<std::string, DatabaseImage> read_database_images(const std::filesystem::path& file) {
  const Database db = open_database(file);
  sqlite3_stmt* stmt = prepare(db, "SELECT image_id, camera_id, name FROM images", file);
  std::map<std::string, DatabaseImage> images;
  while (sqlite3_step(stmt) == SQLITE_ROW) {
    const auto* name = reinterpret_cast<const char*>(sqlite3_column_text(stmt, 2));
    images[name ? name : ""] = {uint32_t(sqlite3_column_int64(stmt, 0)),
                                uint32_t(sqlite3_column_int64(stmt, 1))};
  }
  sqlite3_finalize(stmt);
  return images;
}

ColmapModel with_database_ids(const ColmapModel& model, const std::filesystem::path& db) {
  const auto ids = read_database_images(db);
  ColmapModel out;
  for (const auto& [id, image] : model.images) {
    const auto it = ids.find(image.name);
    if (it == ids.end()) throw InputError(db, "the database has no image " + image.name);
    ColmapImage copy = image;
    copy.image_id = it->second.image_id;
    copy.camera_id = it->second.camera_id;
    ColmapCamera camera = model.cameras.at(image.camera_id);
    camera.camera_id = copy.camera_id;
    out.cameras[camera.camera_id] = camera;
    out.images[copy.image_id] = copy;
  }
  return out;
}

}  // namespace splat
