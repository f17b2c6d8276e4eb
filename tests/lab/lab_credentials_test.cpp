// The credentials sg-lab makes (lab/lab_credentials.hpp): one file per process that takes a key,
// of that process's identity, none for lcm-logger or a process that names its own key; the camera
// host's files let their holder vouch as the cameras and vision only, and sign no command.

#include "lab/lab_credentials.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "auth/credentials_file.hpp"
#include "tests/support/subprocess.hpp"

namespace sg::lab {
namespace {

const char* kLab =
    "lab: t\n"
    "hosts:\n"
    "  - {name: eyes, address: 10.0.0.11}\n"
    "  - {name: brain, address: 10.0.0.12}\n"
    "processes:\n"
    "  - {name: cameras, host: eyes, run: [sg-camera-sim]}\n"
    "  - {name: vision, host: eyes, run: [build/bin/sg-vision, --calibration, c.yaml]}\n"
    "  - {name: predictor, host: brain, run: [sg-predictor]}\n"
    "  - {name: grasp, host: brain, run: [sg-grasp]}\n"
    "  - {name: bench, host: brain, run: [sg-grasp, --insecure-no-key]}\n"
    "  - {name: logger2, host: brain, run: [lcm-logger, x.lcmlog]}\n";

auth::LabKey key() {
  std::array<uint8_t, auth::LabKey::kSize> b{};
  b.fill(9);
  return auth::LabKey(b);
}

// Each process that takes a key gets its identity's file under the session; the others none.
TEST(LabCredentials, OneFilePerProcessOfItsIdentity) {
  const LabFile lab = parse_lab_file(kLab, "lab.yaml");
  const std::string stage = test::make_temp_dir();
  const auto files = stage_credentials(lab, key(), "t-1", stage);
  ASSERT_EQ(files.size(), 4u);
  EXPECT_EQ(files.at("vision"), ".sg-lab/credentials/t-1/vision.cred");
  EXPECT_EQ(files.count("bench"), 0u);    // it names its own key
  EXPECT_EQ(files.count("logger2"), 0u);  // lcm-logger takes none
  const std::map<std::string, std::string> identity = {{"cameras", "sg-camera-sim"},
                                                       {"vision", "sg-vision"},
                                                       {"predictor", "sg-predictor"},
                                                       {"grasp", "sg-grasp"}};
  for (const auto& [name, path] : files) {
    const auth::Credentials c = auth::load_key_file(stage + "/" + path, identity.at(name));
    EXPECT_EQ(c.identity, identity.at(name));
    EXPECT_EQ(c.command_key.has_value(), name == "grasp") << name;
  }
}

// What the cameras' host holds lets it vouch as sg-camera-sim to sg-vision, but sg-grasp refuses
// a forecast vouched for with it, and it holds no command key.
TEST(LabCredentials, TheCameraHostCanSpeakOnlyAsItsProcesses) {
  const LabFile lab = parse_lab_file(kLab, "lab.yaml");
  const std::string stage = test::make_temp_dir();
  const auto files = stage_credentials(lab, key(), "t-1", stage);
  auth::DataGuard cameras(auth::load_key_file(stage + "/" + files.at("cameras"), "sg-camera-sim"));
  auth::DataGuard vision(auth::credentials_from_lab_key(key(), "sg-vision"));
  auth::DataGuard grasp(auth::credentials_from_lab_key(key(), "sg-grasp"));
  std::vector<uint8_t> image = {1, 2, 3}, forecast = {4, 5, 6};
  cameras.vouch("CAMERA_LEFT", image);
  cameras.vouch("OBJECT_TRAJECTORY", forecast);
  EXPECT_TRUE(vision.check("CAMERA_LEFT", image.data(), image.size(), now_utime()).accepted());
  EXPECT_EQ(grasp.check("OBJECT_TRAJECTORY", forecast.data(), forecast.size(), now_utime()).verdict,
            GuardVerdict::kNotAllowed);
  EXPECT_FALSE(auth::load_key_file(stage + "/" + files.at("cameras"), "sg-camera-sim").command_key);
}

// The lab file's `rights:` over the system's table: a new channel (a baseline predictor's) and a
// channel's row replaced (OBJECT_POSITION read by sg-predictor alone); the credentials follow it.
TEST(LabCredentials, TheLabFilesRightsGoIntoTheCredentials) {
  const LabFile lab = parse_lab_file(
      std::string(kLab) +
          "rights:\n"
          "  - {channel: OBJECT_TRAJECTORY_KALMAN, publishers: [sg-predictor], readers: "
          "[sg-grasp]}\n"
          "  - {channel: OBJECT_POSITION, publishers: [sg-vision], readers: [sg-predictor]}\n",
      "lab.yaml");
  const std::string stage = test::make_temp_dir();
  const auto files = stage_credentials(lab, key(), "t-1", stage);
  const auth::Credentials grasp = auth::load_key_file(stage + "/" + files.at("grasp"), "sg-grasp");
  std::vector<std::string> believes;
  for (const auth::Peer& p : grasp.receive)
    for (const std::string& c : p.channels)
      if (c != "PROCESS_STATUS") believes.push_back(p.name + " " + c);
  std::sort(believes.begin(), believes.end());
  EXPECT_EQ(believes,
            (std::vector<std::string>{"sg-arm-driver ARM_STATUS", "sg-grasp-ctl GRASP_COMMAND",
                                      "sg-predictor OBJECT_TRAJECTORY",
                                      "sg-predictor OBJECT_TRAJECTORY_KALMAN"}));
  // A bad entry is refused with its line.
  try {
    parse_lab_file(std::string(kLab) + "rights:\n  - {channel: X, publishers: [a b]}\n",
                   "lab.yaml");
    ADD_FAILURE() << "a bad publisher name was accepted";
  } catch (const LabError& e) {
    EXPECT_NE(std::string(e.what()).find("lab.yaml:13:5:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'a b' is not a program's name"), std::string::npos)
        << e.what();
  }
}

// Which processes take a key, and which name their own.
TEST(LabCredentials, WhoTakesAKey) {
  ProcessSpec p;
  p.run = {"/opt/sg/build/bin/sg-arm-driver", "--device", "/dev/ttyS0"};
  EXPECT_EQ(identity_of(p), "sg-arm-driver");
  EXPECT_FALSE(names_its_key(p));
  p.run.push_back("--key=/etc/sg/driver.cred");
  EXPECT_TRUE(names_its_key(p));
  p.run = {"lcm-logger"};
  EXPECT_EQ(identity_of(p), "");
  p.run = {"sg-bus-check", "health"};
  EXPECT_EQ(identity_of(p), "");
}

}  // namespace
}  // namespace sg::lab
