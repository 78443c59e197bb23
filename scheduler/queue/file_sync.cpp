// Output files made durable (worker.h): written, fsynced, and their folders fsynced, with the
// errno's text in every error (a full disk may show only at fsync).
#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "scheduler/queue/worker.h"
#include "scheduler/queue/queue_internal.h"

namespace gravsweep::queue {

void fsync_path(const fs::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

void write_file_synced(const fs::path& path, const std::string& text) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) throw std::runtime_error(fmt::format("cannot create '{}': {}", path.string(), std::strerror(errno)));
  std::size_t off = 0;
  while (off < text.size()) {
    const ssize_t n = ::write(fd, text.data() + off, text.size() - off);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      throw std::runtime_error(fmt::format("cannot write '{}': {}", path.string(), std::strerror(err)));
    }
    off += static_cast<std::size_t>(n);
  }
  // A full disk may show only here (delayed allocation): the data is not safe until fsync says so.
  if (::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    throw std::runtime_error(fmt::format("cannot write '{}' (fsync): {}", path.string(), std::strerror(err)));
  }
  if (::close(fd) != 0)
    throw std::runtime_error(fmt::format("cannot write '{}' (close): {}", path.string(), std::strerror(errno)));
}

}  // namespace gravsweep::queue
