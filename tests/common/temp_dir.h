// A fresh temporary folder for one test, removed at the end of the scope.
#pragma once
#include <unistd.h>

#include <filesystem>
#include <random>
#include <string>
#include <system_error>

namespace gravsweep::test {

struct TempDir {
  std::filesystem::path path;
  explicit TempDir(const std::string& prefix = "gravsweep-test") {
    std::random_device rd;
    path = std::filesystem::temp_directory_path() /
           (prefix + "-" + std::to_string(::getpid()) + "-" + std::to_string(rd()));
    std::filesystem::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] std::string str() const { return path.string(); }
};

}  // namespace gravsweep::test
