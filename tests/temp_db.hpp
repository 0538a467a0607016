// A fresh database file name in the temporary folder, removed with its WAL files at the end.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

namespace rccx::test {

struct TempDb {
  TempDb() {
    static int n = 0;
    path = std::filesystem::temp_directory_path() /
           ("rccx_db_test_" + std::to_string(::getpid()) + "_" + std::to_string(n++) + ".db");
    clean();
  }
  ~TempDb() { clean(); }
  TempDb(const TempDb&) = delete;
  TempDb& operator=(const TempDb&) = delete;
  void clean() const {
    for (const char* s : {"", "-wal", "-shm"}) std::filesystem::remove(path.string() + s);
  }
  std::filesystem::path path;
};

}  // namespace rccx::test
