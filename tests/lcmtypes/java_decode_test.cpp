// C++ to Java: what C++ encodes, Java decodes to equal field values, finding each class by its
// fingerprint exactly as lcm-spy does (lcm.spy.LCMTypeDatabase on CLASSPATH).

#include <gtest/gtest.h>

#include <fstream>

#include "auth/data_auth.hpp"
#include "tests/support/field_dump.hpp"
#include "tests/support/sample_messages.hpp"
#include "tests/support/subprocess.hpp"

namespace sg::test {
namespace {

std::string write_message(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream file(path, std::ios::binary);
  file.write(reinterpret_cast<const char*>(bytes.data()),
             static_cast<std::streamsize>(bytes.size()));
  return path;
}

// Every type, with empty, typical and extreme values, decodes in Java to the same fields.
TEST(JavaDecode, EveryTypeDecodesToEqualFieldsThroughLcmSpysTypeDatabase) {
  const std::string dir = make_temp_dir();
  std::vector<std::string> argv = {"java", "-cp", SG_JAVA_CLASSPATH, "LcmDump"};
  std::string expected;
  int n = 0;
  for (SampleKind kind : {SampleKind::kEmpty, SampleKind::kTypical, SampleKind::kExtreme}) {
    for_each_message_type([&]<class T>() {
      const T message = make_sample<T>(kind);
      argv.push_back(
          write_message(dir + "/" + std::to_string(n++) + ".bin", encode_message(message)));
      expected += dump(message) + "\n";
    });
  }
  const ProcessResult java = run(argv, std::chrono::seconds(120));
  ASSERT_EQ(java.exit_code, 0) << java.err;
  EXPECT_EQ(java.out.find("unknown="), std::string::npos) << "lcm-spy would not know a type";
  EXPECT_EQ(java.out, expected);
}

// Vouched for (the trailer of every datum vouched for after the encoding, docs/security.md), every
// type still decodes in Java, as lcm-spy finds and decodes it, to the same fields: the trailer is
// read past, not into the message.
TEST(JavaDecode, VouchedMessagesDecodeToTheSameFields) {
  std::array<uint8_t, auth::LabKey::kSize> key{};
  key.fill(7);
  auth::DataGuard guard(auth::credentials_from_lab_key(auth::LabKey(key), "sg-predictor"));
  const std::string dir = make_temp_dir();
  std::vector<std::string> argv = {"java", "-cp", SG_JAVA_CLASSPATH, "LcmDump"};
  std::string expected;
  int n = 0;
  for_each_message_type([&]<class T>() {
    const T message = make_sample<T>(SampleKind::kTypical);
    std::vector<uint8_t> bytes = encode_message(message);
    const size_t plain = bytes.size();
    guard.vouch("PROCESS_STATUS", bytes);  // a trailer with 12 tags: the longest there is
    EXPECT_GT(bytes.size(), plain + 12 * 16);
    argv.push_back(write_message(dir + "/" + std::to_string(n++) + ".bin", bytes));
    expected += dump(message) + "\n";
  });
  const ProcessResult java = run(argv, std::chrono::seconds(120));
  ASSERT_EQ(java.exit_code, 0) << java.err;
  EXPECT_EQ(java.out, expected);
}

// A message whose fingerprint is not a stereograsp type is reported unknown, not misread.
TEST(JavaDecode, ForeignFingerprintIsUnknown) {
  std::vector<uint8_t> bytes =
      encode_message(make_sample<stereograsp::point3_t>(SampleKind::kTypical));
  bytes[0] ^= 0x5a;  // corrupt the fingerprint
  const std::string dir = make_temp_dir();
  const ProcessResult java =
      run({"java", "-cp", SG_JAVA_CLASSPATH, "LcmDump", write_message(dir + "/foreign.bin", bytes)},
          std::chrono::seconds(60));
  ASSERT_EQ(java.exit_code, 0) << java.err;
  EXPECT_EQ(java.out.rfind("unknown=", 0), 0u) << java.out;
}

}  // namespace
}  // namespace sg::test
