#pragma once

/// The commands mac_check_fuzz knows to be signed, and its input format, shared with
/// sg_fuzz_seeds (fuzz/seeds.cpp) so the committed seeds and the target agree to the byte.
///
/// An input is up to kMaxRecords records, each
///     selector (1 byte) || length (2 bytes, big-endian) || that many bytes (fewer at the end),
/// the selector picking the type (bit 0: arm_cmd_t or grasp_command_t), the channel it arrives
/// on (bits 1-2: kChannels) and the receiver's clock (bits 3-7: now = kNow + (s - 16) * 4 s, so
/// 16 is kNow itself). Everything here is deterministic: a fixed key (not a secret: only the
/// fuzzer uses it), a fixed clock, fixed senders.

#include <array>
#include <cstdint>
#include <cstring>
#include <functional>
#include <mutex>
#include <stop_token>
#include <string>
#include <vector>

#include "auth/command_auth.hpp"
#include "auth/lab_key.hpp"
#include "common/clock.hpp"
#include "common/message_types.hpp"

namespace sg::fuzz {

constexpr std::size_t kMaxRecords = 8;
/// µs since the Unix epoch: the receiver's clock at selector 16 (2023-11-14T22:13:20Z).
constexpr int64_t kNow = 1'700'000'000'000'000;
/// The signer's clock: a second before kNow.
constexpr int64_t kSignedAt = kNow - 1'000'000;
inline const std::array<std::string, 4> kChannels = {"ARM_COMMAND", "GRASP_COMMAND",
                                                     "ARM_COMMAND_SIM", ""};

/// The key every signed command carries a tag of: bytes 0, 1, ..., 31.
inline auth::LabKey fuzz_key() {
  std::array<uint8_t, auth::LabKey::kSize> bytes{};
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<uint8_t>(i);
  return auth::LabKey(bytes);
}
/// Another key (bytes 255, 254, ...): its tags must be refused as kBadTag.
inline auth::LabKey other_key() {
  std::array<uint8_t, auth::LabKey::kSize> bytes{};
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<uint8_t>(255 - i);
  return auth::LabKey(bytes);
}

/// A clock that always reads kSignedAt (the signer's counter floor); never waited on.
class FixedClock final : public Clock {
 public:
  double now() override { return 0.0; }
  int64_t utime() override { return kSignedAt; }
  bool wait_until(std::unique_lock<std::mutex>&, double, const std::function<bool()>& ready,
                  std::stop_token = {}) override {
    return ready();
  }
  void notify() override {}
  void sleep_until(double) override {}
};

/// One command as it travels: its channel and its encoded bytes.
struct SignedCommand {
  bool grasp = false;  ///< grasp_command_t, else arm_cmd_t
  int channel = 0;     ///< index into kChannels
  std::vector<uint8_t> bytes;
};

/// A motion command of the kind sg-grasp sends.
inline stereograsp::arm_cmd_t arm_move(int64_t sequence) {
  stereograsp::arm_cmd_t c{};
  c.utime = kSignedAt;
  c.sequence = sequence;
  c.mode = stereograsp::arm_cmd_t::MODE_CARTESIAN;
  c.position[0] = 0.45;
  c.position[2] = 0.12;
  c.orientation[1] = 3.14159;
  c.gripper = stereograsp::arm_cmd_t::GRIPPER_OPEN;
  c.speed = 0.5;
  return c;
}

inline stereograsp::grasp_command_t grasp(int64_t sequence) {
  stereograsp::grasp_command_t c{};
  c.utime = kSignedAt;
  c.sequence = sequence;
  c.command = stereograsp::grasp_command_t::COMMAND_GRASP;
  c.standoff = 0.05;
  return c;
}

/// The commands signed with fuzz_key(): two ARM_COMMANDs from "sg-grasp@fuzz:1" (counters
/// kSignedAt and kSignedAt + 1) and one GRASP_COMMAND from "sg-grasp-ctl@fuzz:2". These, on
/// their channel, are the only inputs the verifier may ever accept.
inline std::vector<SignedCommand> signed_commands() {
  FixedClock clock;
  auth::CommandSigner arm(fuzz_key(), "sg-grasp@fuzz:1", clock);
  auth::CommandSigner ctl(fuzz_key(), "sg-grasp-ctl@fuzz:2", clock);
  std::vector<SignedCommand> out;
  for (int64_t sequence : {1, 2}) {
    stereograsp::arm_cmd_t c = arm_move(sequence);
    arm.sign(kChannels[0], c);
    out.push_back({false, 0, encode_message(c)});
  }
  stereograsp::grasp_command_t g = grasp(7);
  ctl.sign(kChannels[1], g);
  out.push_back({true, 1, encode_message(g)});
  return out;
}

/// The same first ARM_COMMAND unsigned (zero tag), and signed with other_key().
inline std::vector<SignedCommand> unsigned_and_wrong_key() {
  FixedClock clock;
  stereograsp::arm_cmd_t c = arm_move(1);
  c.sender = "sg-grasp@fuzz:1";
  c.auth_counter = kSignedAt;
  std::vector<SignedCommand> out{{false, 0, encode_message(c)}};
  auth::CommandSigner forger(other_key(), "sg-grasp@fuzz:1", clock);
  forger.sign(kChannels[0], c);
  out.push_back({false, 0, encode_message(c)});
  return out;
}

/// The selector of a record: its type, channel and the receiver's clock step (16: kNow).
inline uint8_t selector(bool grasp, int channel, int clock_step = 16) {
  return static_cast<uint8_t>((grasp ? 1 : 0) | (channel << 1) | (clock_step << 3));
}

/// Appends one record holding `command` (at the receiver's clock step 16) to `input`.
inline void append_record(std::vector<uint8_t>& input, const SignedCommand& command) {
  input.push_back(selector(command.grasp, command.channel));
  input.push_back(static_cast<uint8_t>(command.bytes.size() >> 8));
  input.push_back(static_cast<uint8_t>(command.bytes.size()));
  input.insert(input.end(), command.bytes.begin(), command.bytes.end());
}

}  // namespace sg::fuzz
