// A process's credentials in a file (auth/credentials_file.hpp): written and read back equal, mode
// 0600; a guard made from the file and one made from the lab key believe each other; every kind of
// bad line refused with its line number; a file of another identity refused; the lab key itself
// still accepted by the same loader.

#include "auth/credentials_file.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <fstream>

#include "tests/support/subprocess.hpp"

namespace sg::auth {
namespace {

LabKey key_of(uint8_t seed) {
  std::array<uint8_t, LabKey::kSize> b{};
  for (size_t i = 0; i < b.size(); ++i) b[i] = static_cast<uint8_t>(seed + 3 * i);
  return LabKey(b);
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
  chmod(path.c_str(), 0600);
}

// sg-grasp's credentials round trip through a file of mode 0600, command key included; sg-vision's
// carry none.
TEST(CredentialsFile, WrittenAndReadBackEqual) {
  const std::string dir = test::make_temp_dir();
  for (const char* who : {"sg-grasp", "sg-vision"}) {
    const Credentials c = credentials_from_lab_key(key_of(1), who);
    const std::string path = dir + "/" + who + ".cred";
    write_credentials_file(path, c, std::string("test, ") + who);
    struct stat st {};
    ASSERT_EQ(stat(path.c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 0777, 0600u);
    const Credentials back = load_key_file(path, who);
    EXPECT_TRUE(same_credentials(c, back)) << who;
    EXPECT_EQ(back.command_key.has_value(), std::string(who) == "sg-grasp");
  }
}

// A guard from sg-predictor's file and one from the lab key as sg-grasp believe each other's
// messages both ways (PROCESS_STATUS), and sg-grasp believes the file's forecasts.
TEST(CredentialsFile, FileAndLabKeyGuardsAgree) {
  const std::string dir = test::make_temp_dir();
  write_credentials_file(dir + "/p.cred", credentials_from_lab_key(key_of(2), "sg-predictor"), "");
  DataGuard predictor(load_key_file(dir + "/p.cred", "sg-predictor"));
  DataGuard grasp(credentials_from_lab_key(key_of(2), "sg-grasp"));
  std::vector<uint8_t> m = {1, 2, 3}, s = {4, 5, 6};
  predictor.vouch("OBJECT_TRAJECTORY", m);
  grasp.vouch("PROCESS_STATUS", s);
  EXPECT_TRUE(grasp.check("OBJECT_TRAJECTORY", m.data(), m.size(), now_utime()).accepted());
  EXPECT_TRUE(predictor.check("PROCESS_STATUS", s.data(), s.size(), now_utime()).accepted());
}

// Each bad file is refused with the line that is wrong.
TEST(CredentialsFile, BadLinesAreRefusedWithTheirLine) {
  const std::string dir = test::make_temp_dir();
  const std::string k(64, 'a');
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"identity a\nstereograsp-credentials 1\n", ":1: expected 'stereograsp-credentials 1' first"},
      {"stereograsp-credentials 1\n", "no identity"},
      {"stereograsp-credentials 1\nidentity a b\n", ":2: unexpected 'b'"},
      {"stereograsp-credentials 1\nidentity sg vision\n", ":2: unexpected 'vision'"},
      {"stereograsp-credentials 1\nidentity a\nidentity b\n", ":3: a second identity"},
      {"stereograsp-credentials 1\nidentity a\nsend b 1234 X\n", ":3: a key is 64 hex"},
      {"stereograsp-credentials 1\nidentity a\nsend b " + k + "\n", ":3: expected a comma"},
      {"stereograsp-credentials 1\nidentity a\nsend b " + k + " X,,Y\n", ":3: not a channel: ''"},
      {"stereograsp-credentials 1\nidentity a\nsend b " + k + " X\nsend b " + k + " Y\n",
       ":4: send b named twice"},
      {"stereograsp-credentials 1\nidentity a\nreceive b\xff " + k + " X\n", ":3: not a peer name"},
      {"stereograsp-credentials 1\nidentity a\nallow b\n", ":3: unknown word 'allow'"},
      {"stereograsp-credentials 1\nidentity a\ncommand-key zz\n", ":3: a key is 64 hex"},
  };
  for (const auto& [text, why] : cases) {
    const std::string path = dir + "/bad.cred";
    write_text(path, text);
    try {
      load_key_file(path, "a");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const LabKeyError& e) {
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what() << " for " << text;
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  }
}

// Credentials of another process are refused; so is a file others may read, or a huge one.
TEST(CredentialsFile, AnotherIdentityOrAnOpenFileIsRefused) {
  const std::string dir = test::make_temp_dir();
  write_credentials_file(dir + "/v.cred", credentials_from_lab_key(key_of(3), "sg-vision"), "");
  EXPECT_THROW(load_key_file(dir + "/v.cred", "sg-predictor"), LabKeyError);
  chmod((dir + "/v.cred").c_str(), 0644);
  EXPECT_THROW(load_key_file(dir + "/v.cred", "sg-vision"), LabKeyError);
  write_text(dir + "/big.cred", "stereograsp-credentials 1\n" + std::string(70000, '#'));
  EXPECT_THROW(load_key_file(dir + "/big.cred", "sg-vision"), LabKeyError);
}

// The lab key itself still loads, as every pair derived.
TEST(CredentialsFile, TheLabKeyLoadsAsEveryPair) {
  const std::string path = test::make_temp_dir() + "/lab.key";
  write_new_key_file(path);
  EXPECT_TRUE(same_credentials(load_key_file(path, "sg-grasp"),
                               credentials_from_lab_key(LabKey::load(path), "sg-grasp")));
}

}  // namespace
}  // namespace sg::auth
