// Canonical JSON and content hashes: the same parameters always give the same job id.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "spec/json_pointer.h"
#include "scheduler/queue/canonical.h"

using gravsweep::queue::canonical_json;
using gravsweep::queue::job_id;
using gravsweep::queue::round_decimal;
using gravsweep::queue::sha256_hex;
using nlohmann::json;

TEST(Sha256, KnownVectors) {
  // FIPS 180-2 appendix B examples.
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(sha256_hex(std::string(1000000, 'a')), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Canonical, SortedKeysNoWhitespace) {
  const json a = json::parse(R"({"b": 1, "a": {"y": [1, 2], "x": "s"}})");
  EXPECT_EQ(canonical_json(a), R"({"a":{"x":"s","y":[1,2]},"b":1})");
}

TEST(Canonical, NumbersByValue) {
  // 1, 1.0 and 1e0 are one parameter; -0 is 0; non-integral values keep the shortest round trip.
  EXPECT_EQ(canonical_json(json::parse("1.0")), "1");
  EXPECT_EQ(canonical_json(json::parse("1e0")), "1");
  EXPECT_EQ(canonical_json(json::parse("-0.0")), "0");
  EXPECT_EQ(canonical_json(json::parse("9.81")), "9.81");
  EXPECT_EQ(canonical_json(json::parse("0.1")), "0.1");
  EXPECT_EQ(canonical_json(json::parse("1e-06")), canonical_json(json::parse("0.000001")));
  EXPECT_EQ(job_id("drop", json::parse(R"({"g": 1.0, "v": 2})")), job_id("drop", json::parse(R"({"v": 2.0, "g": 1})")));
  EXPECT_NE(job_id("drop", json::parse(R"({"g": 1})")), job_id("bed", json::parse(R"({"g": 1})")));
  EXPECT_NE(job_id("drop", json::parse(R"({"g": 1.0000001})")), job_id("drop", json::parse(R"({"g": 1})")));
}

TEST(Canonical, RangeArithmeticHasNoFloatSurprises) {
  // 0.1 + 0.2 is 0.30000000000000004 in binary; the rounded value hashes like the literal 0.3.
  const double sum = 0.1 + 0.2;
  EXPECT_NE(sum, 0.3);
  EXPECT_EQ(round_decimal(sum), 0.3);
  EXPECT_EQ(canonical_json(json(round_decimal(sum))), "0.3");
  EXPECT_EQ(canonical_json(json(round_decimal(3 * 0.1))), canonical_json(json::parse("0.3")));
}

TEST(Canonical, RejectsNonFinite) {
  json j = {{"a", {{"b", std::nan("")}}}};
  try {
    canonical_json(j);
    FAIL() << "NaN accepted";
  } catch (const gravsweep::queue::CanonicalError& e) {
    EXPECT_NE(std::string(e.what()).find("/a/b"), std::string::npos) << e.what();
  }
}

TEST(JsonPointer, TokensAreEscapedAsRfc6901Says) {
  using gravsweep::spec::pointer_child;
  using gravsweep::spec::pointer_token;
  EXPECT_EQ(pointer_token("gravity_m_s2"), "gravity_m_s2");
  EXPECT_EQ(pointer_token("a/b~c"), "a~1b~0c");
  EXPECT_EQ(pointer_token("~1"), "~01");  // '~' first, so "~1" is not read back as '/'
  EXPECT_EQ(pointer_child("", "x/y"), "/x~1y");
  EXPECT_EQ(pointer_child("/base", "m~s"), "/base/m~0s");
  // The pointer a message names is the one nlohmann reads back to the same member.
  const json j = {{"a/b", {{"c~d", 1}}}};
  EXPECT_EQ(j.at(json::json_pointer(pointer_child(pointer_child("", "a/b"), "c~d"))), 1);
}

TEST(Canonical, RejectsNonFiniteNamingAnEscapedPointer) {
  json j = {{"a/b", {{"c~d", std::nan("")}}}};
  try {
    canonical_json(j);
    FAIL() << "NaN accepted";
  } catch (const gravsweep::queue::CanonicalError& e) {
    EXPECT_NE(std::string(e.what()).find("/a~1b/c~0d"), std::string::npos) << e.what();
  }
}
