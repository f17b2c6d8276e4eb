// The lab key file (auth/lab_key.hpp) and the programs' key flags (auth/lab_access.hpp): a round
// trip, and every refusal with its one-line reason.

#include "auth/lab_key.hpp"

#include <gtest/gtest.h>
#include <sodium.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "auth/lab_access.hpp"
#include "common/program.hpp"
#include "tests/support/subprocess.hpp"

namespace sg::auth {
namespace {

/// Writes `text` to `path` with `mode`.
void write_file(const std::string& path, const std::string& text, mode_t mode) {
  std::ofstream(path) << text;
  ::chmod(path.c_str(), mode);
}

/// The message LabKey::load(path) throws ("" when it loads).
std::string load_error(const std::string& path) {
  try {
    LabKey::load(path);
    return "";
  } catch (const LabKeyError& e) {
    return e.what();
  }
}

mode_t mode_of(const std::string& path) {
  struct stat st {};
  ::stat(path.c_str(), &st);
  return st.st_mode & 07777;
}

const std::string kHex = "00112233445566778899aabbccddeeff00112233445566778899AABBCCDDEEFF";

// A new key file is 64 hex characters and a newline, mode 0600, and loads back as its bytes.
TEST(LabKey, WriteAndLoadRoundTrip) {
  const std::string path = test::make_temp_dir() + "/sub/lab.key";
  write_new_key_file(path);
  EXPECT_EQ(mode_of(path), 0600u);
  const std::string text = test::read_text(path);
  ASSERT_EQ(text.size(), 65u);
  EXPECT_EQ(text.back(), '\n');
  EXPECT_EQ(text.find_first_not_of("0123456789abcdef"), 64u);
  const LabKey key = LabKey::load(path);
  for (std::size_t i = 0; i < LabKey::kSize; ++i) {
    EXPECT_EQ(key.bytes()[i], std::stoi(text.substr(2 * i, 2), nullptr, 16)) << i;
  }
  EXPECT_EQ(mode_of(std::filesystem::path(path).parent_path()), 0700u);  // the folder it made
}

// A key file given by hand (upper-case hex, no newline) loads to the bytes it spells.
TEST(LabKey, LoadsKnownBytes) {
  const std::string path = test::make_temp_dir() + "/lab.key";
  write_file(path, kHex, 0600);
  const LabKey key = LabKey::load(path);
  EXPECT_EQ(key.bytes()[0], 0x00);
  EXPECT_EQ(key.bytes()[1], 0x11);
  EXPECT_EQ(key.bytes()[15], 0xff);
  EXPECT_EQ(key.bytes()[31], 0xff);
}

// An existing key is not overwritten; with replace it is, by a different random key, still 0600.
TEST(LabKey, RefusesToOverwriteUnlessReplacing) {
  const std::string path = test::make_temp_dir() + "/lab.key";
  write_new_key_file(path);
  const std::string first = test::read_text(path);
  try {
    write_new_key_file(path);
    FAIL() << "overwrote an existing key";
  } catch (const LabKeyError& e) {
    EXPECT_NE(std::string(e.what()).find("already exists"), std::string::npos) << e.what();
  }
  EXPECT_EQ(test::read_text(path), first);
  write_new_key_file(path, /*replace=*/true);
  EXPECT_NE(test::read_text(path), first);
  EXPECT_EQ(mode_of(path), 0600u);
  EXPECT_FALSE(std::filesystem::exists(path + ".new"));
}

// Mode 0644 (and 0640, 0604) is refused with the path and "chmod 600".
TEST(LabKey, RefusesAKeyOthersCanRead) {
  const std::string path = test::make_temp_dir() + "/lab.key";
  for (mode_t mode : {0644, 0640, 0604, 0660}) {
    write_file(path, kHex + "\n", mode);
    const std::string error = load_error(path);
    EXPECT_NE(error.find(path), std::string::npos) << error;
    EXPECT_NE(error.find("chmod 600"), std::string::npos) << error;
  }
  write_file(path, kHex + "\n", 0400);  // read-only for its owner is fine
  EXPECT_EQ(load_error(path), "");
}

// Too short, too long, not hex, missing, a folder: each refused with the path and the reason.
TEST(LabKey, RefusesMalformedOrMissingFiles) {
  const std::string dir = test::make_temp_dir();
  const std::string path = dir + "/lab.key";
  write_file(path, kHex.substr(0, 63) + "\n", 0600);
  EXPECT_EQ(load_error(path),
            "lab key " + path + ": expected 64 hex characters and a newline, got 63 characters");
  write_file(path, kHex + "00\n", 0600);
  EXPECT_NE(load_error(path).find("got 66 characters"), std::string::npos);
  write_file(path, "", 0600);
  EXPECT_NE(load_error(path).find("got 0 characters"), std::string::npos);
  write_file(path, kHex.substr(0, 63) + "g\n", 0600);
  EXPECT_EQ(load_error(path), "lab key " + path + ": not hex: expected 64 characters 0-9 a-f");
  write_file(path, kHex + "\n\n", 0600);
  EXPECT_NE(load_error(path).find("got 65 characters"), std::string::npos);
  EXPECT_EQ(load_error(dir + "/absent.key"), "lab key " + dir + "/absent.key: no such file");
  EXPECT_EQ(load_error(dir), "lab key " + dir + ": not a regular file");
}

// The default path: $SG_LAB_KEY, else $HOME/.config/stereograsp/lab.key.
TEST(LabKey, DefaultPath) {
  const char* saved = std::getenv("SG_LAB_KEY");
  const std::string keep = saved ? saved : "";
  const char* saved_home = std::getenv("HOME");
  const std::string keep_home = saved_home ? saved_home : "";
  ::setenv("SG_LAB_KEY", "/somewhere/lab.key", 1);
  EXPECT_EQ(default_key_path(), "/somewhere/lab.key");
  ::setenv("SG_LAB_KEY", "", 1);
  ::setenv("HOME", "/home/op", 1);
  EXPECT_EQ(default_key_path(), "/home/op/.config/stereograsp/lab.key");
  if (saved) ::setenv("SG_LAB_KEY", keep.c_str(), 1);
  if (saved_home) ::setenv("HOME", keep_home.c_str(), 1);
}

// Without a key and without --insecure-no-key the program's body never runs and it exits 2.
TEST(LabAccess, NoKeyExitsTwo) {
  KeyOptions options;
  options.path = test::make_temp_dir() + "/absent.key";
  bool ran = false;
  testing::internal::CaptureStderr();
  const int rc = with_lab_access("sg-test", options, [&](LabAccess&) {
    ran = true;
    return 0;
  });
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(rc, kExitNoKey);
  EXPECT_FALSE(ran);
  EXPECT_NE(err.find("sg-test: error: lab key " + options.path +
                     ": no such file; make one with "
                     "`sg-keygen " +
                     options.path + "`"),
            std::string::npos)
      << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1);
}

// --insecure-no-key: the body runs without a key, signs nothing and accepts an unsigned command.
TEST(LabAccess, InsecureSignsNothingAndAcceptsAll) {
  KeyOptions options;
  options.insecure = true;
  const int rc = with_lab_access("sg-test", options, [&](LabAccess& lab) {
    EXPECT_FALSE(lab.secure());
    stereograsp::arm_cmd_t c{};
    c.sequence = 3;
    lab.sign("ARM_COMMAND", c);
    EXPECT_EQ(c.sender, sg::instance_name("sg-test"));  // sg-test@<host>:<pid>
    EXPECT_EQ(c.sender.rfind("sg-test@", 0), 0u);
    EXPECT_TRUE(c.sender.ends_with(":" + std::to_string(getpid())));
    EXPECT_EQ(c.auth_counter, 0);
    for (uint8_t b : c.auth_tag) EXPECT_EQ(b, 0);
    EXPECT_EQ(lab.refusal("ARM_COMMAND", c, 1'000'000), "");
    return 7;
  });
  EXPECT_EQ(rc, 7);
}

// With a key: the LabAccess of a program that sends commands (sg-grasp-ctl) signs, and refuses
// unsigned commands as "unauthenticated: ...".
TEST(LabAccess, WithAKeySignsAndChecks) {
  KeyOptions options;
  options.path = test::make_temp_dir() + "/lab.key";
  write_new_key_file(options.path);
  const int rc = with_lab_access("sg-grasp-ctl", options, [&](LabAccess& lab) {
    EXPECT_TRUE(lab.secure());
    EXPECT_TRUE(lab.command_key().has_value());
    if (!lab.command_key()) return 1;
    EXPECT_EQ(lab.command_key()->bytes(), command_key(LabKey::load(options.path)).bytes());
    stereograsp::grasp_command_t unsigned_command{};
    unsigned_command.sender = "sg-test";
    EXPECT_EQ(lab.refusal("GRASP_COMMAND", unsigned_command, 1'000'000)
                  .rfind("unauthenticated: unsigned", 0),
              0u);
    stereograsp::grasp_command_t c{};
    lab.sign("GRASP_COMMAND", c);
    EXPECT_EQ(lab.refusal("GRASP_COMMAND", c, c.auth_counter), "");
    EXPECT_EQ(lab.verifier()->count(Verdict::kAccepted), 1);
    EXPECT_EQ(lab.verifier()->count(Verdict::kUnsigned), 1);
    return 0;
  });
  EXPECT_EQ(rc, 0);
}

// A program that neither sends nor obeys commands (sg-predictor) holds no command key, even from
// the lab key: it cannot sign one, and it obeys none.
TEST(LabAccess, WithoutCommandRightsNoCommandIsSignedOrObeyed) {
  KeyOptions options;
  options.path = test::make_temp_dir() + "/lab.key";
  write_new_key_file(options.path);
  const int rc = with_lab_access("sg-predictor", options, [&](LabAccess& lab) {
    EXPECT_TRUE(lab.secure());
    EXPECT_FALSE(lab.command_key().has_value());
    stereograsp::grasp_command_t c{};
    EXPECT_THROW(lab.sign("GRASP_COMMAND", c), std::runtime_error);
    EXPECT_EQ(lab.refusal("GRASP_COMMAND", c, 1),
              "unauthenticated: sg-predictor holds no command key");
    return 0;
  });
  EXPECT_EQ(rc, 0);
}

// The keys of a lab's generations: generation 0 is the lab key; each other one is the documented
// BLAKE2b of it, and differs from the others; the command key is BLAKE2b of its own label.
TEST(LabKey, GenerationsAndTheCommandKeyAreTheDocumentedBlake2b) {
  std::array<uint8_t, LabKey::kSize> b{};
  b.fill(3);
  const LabKey lab(b);
  EXPECT_EQ(generation_key(lab, 0).bytes(), lab.bytes());
  const std::string label = std::string("sg-generation-v1") + std::string("\0\0\0\x02", 4);
  std::array<uint8_t, 32> two{};
  crypto_generichash(two.data(), 32, reinterpret_cast<const unsigned char*>(label.data()),
                     label.size(), lab.bytes().data(), 32);
  EXPECT_EQ(generation_key(lab, 2).bytes(), two);
  EXPECT_NE(generation_key(lab, 1).bytes(), generation_key(lab, 2).bytes());
  std::array<uint8_t, 32> command{};
  crypto_generichash(command.data(), 32, reinterpret_cast<const unsigned char*>("sg-command-v1"),
                     13, lab.bytes().data(), 32);
  EXPECT_EQ(command_key(lab).bytes(), command);
}

}  // namespace
}  // namespace sg::auth
