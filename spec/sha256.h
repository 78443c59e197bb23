// SHA-256 (FIPS 180-4): the one content hash of the project (job ids and bed checksums in
// scheduler/queue/canonical.h, stored traces in results/measurements/campaign.cpp).
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace gravsweep::spec {

/// Streaming SHA-256.
class Sha256 {
 public:
  Sha256();
  void update(const void* data, std::size_t n);
  std::string hex_digest();  ///< finalises; the object must not be updated afterwards

 private:
  void block(const unsigned char* p);
  std::uint32_t h_[8];
  unsigned char buf_[64];
  std::size_t buf_len_ = 0;
  std::uint64_t total_ = 0;
};

/// SHA-256 of bytes, as 64 lowercase hex digits.
std::string sha256_hex(std::string_view bytes);

}  // namespace gravsweep::spec
