// Canonical JSON and content hashes for job identity.
//
// canonical_json(): object keys sorted (byte order), no whitespace, strings escaped minimally,
// numbers by value: an integral value with |v| < 2^53 is written as an integer whatever its JSON
// type (1, 1.0 and 1e0 are the same parameter), other values as the shortest decimal that
// round-trips the double, -0 becomes 0; NaN and infinities are rejected (CanonicalError).
// job ids are hex SHA-256 prefixes of a kind tag and the canonical text.
#pragma once
#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

#include "spec/sha256.h"

namespace gravsweep::queue {

struct CanonicalError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Canonical text of `j` (see above). Throws CanonicalError naming the JSON pointer of a NaN/Inf.
std::string canonical_json(const nlohmann::json& j);

/// The same value, normalised as canonical_json() writes it (integral floats become integers,
/// -0 becomes 0), so that what is stored and what is hashed agree.
nlohmann::json canonicalize(const nlohmann::json& j);

/// Rounds a computed value (range arithmetic) to 12 significant digits, so that 0.1 + 0.2 gives
/// the same parameter as the literal 0.3.
double round_decimal(double v, int significant_digits = 12);

/// SHA-256 (FIPS 180-4) of bytes, as 64 lowercase hex digits (spec/sha256.h).
using spec::sha256_hex;
/// Streaming SHA-256, for files (spec/sha256.h).
using spec::Sha256;

/// SHA-256 of a file's content; throws std::runtime_error naming the file if it cannot be read.
std::string sha256_file(const std::filesystem::path& path);

/// Job id: the first 20 hex digits of SHA-256("gravsweep-job/1\n" + kind + "\n" + canonical).
std::string job_id(std::string_view kind, const nlohmann::json& params);

}  // namespace gravsweep::queue
