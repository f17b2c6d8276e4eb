#pragma once

/// Checks each ARM_COMMAND before anything reaches the serial line, and turns it into a joint
/// target: finite numbers, a known mode, a speed in (0, 1], a sequence number newer than the last
/// (equal: a duplicate, a resend of a command the driver already has, which is ignored),
/// a tool position inside the workspace box, a pose the arm reaches within its joint limits (the
/// inverse-kinematics solution nearest the reference joints). "The arm never gets a target
/// outside its limits" (DESIGN.md, rule 5) is enforced here.
///
///     CommandValidator validator(ArmGeometry::a465());
///     ValidationResult r = validator.validate(command, current_joints);
///     if (r.target) slot.offer(*r.target); else publish_rejection(command.sequence, r.reason);

#include <map>
#include <optional>
#include <string>

#include "arm_driver/kinematics.hpp"
#include "stereograsp/arm_cmd_t.hpp"

namespace sg::arm {

/// A validated command, ready for the controller.
struct ArmTarget {
  int64_t sequence = 0;
  int8_t mode = stereograsp::arm_cmd_t::MODE_STOP;
  Joints joints = Joints::Zero();  ///< MODE_CARTESIAN and MODE_JOINTS: where to go (radians)
  int8_t gripper = stereograsp::arm_cmd_t::GRIPPER_KEEP;
  double speed = 0.5;              ///< fraction of the joint speed limits
  int64_t source_utime = 0;
  std::string sender;
  /// The driver's own command (the watchdog's STOP): no sender's sequence, so executing it
  /// changes neither last_executed_sequence nor last_rejected_sequence.
  bool internal = false;
  bool moves_arm() const {
    return mode == stereograsp::arm_cmd_t::MODE_CARTESIAN ||
           mode == stereograsp::arm_cmd_t::MODE_JOINTS;
  }
};

struct ValidationResult {
  std::optional<ArmTarget> target;
  std::string reason;      ///< why it was rejected, when target is empty
  bool duplicate = false;  ///< the sequence equals its sender's last: ignored, not a rejection
};

class CommandValidator {
 public:
  explicit CommandValidator(ArmGeometry geometry) : geometry_(std::move(geometry)) {}

  /// Checks `command`; `reference` is where the arm will be when the command runs (the pending
  /// target, else the current joints), from which the nearest IK solution is chosen. Sequence
  /// numbers are per sender (sg-grasp counts, sg-arm-ctl uses its clock); every command
  /// received, accepted or not, advances its sender's last sequence number. A sequence equal to
  /// the sender's last is a duplicate (sg-grasp resending a command it fears was lost): no
  /// target, `duplicate` set. Not for MODE_HEARTBEAT and MODE_RELEASE, which consume no sequence.
  ValidationResult validate(const stereograsp::arm_cmd_t& command, const Joints& reference);
  const ArmGeometry& geometry() const { return geometry_; }
  /// The last sequence received from `sender`, -1 when none.
  int64_t last_sequence(const std::string& sender) const;

 private:
  ValidationResult reject(std::string reason) const { return {std::nullopt, std::move(reason)}; }
  ValidationResult cartesian(const stereograsp::arm_cmd_t& command, const Joints& reference,
                             ArmTarget target) const;
  ValidationResult joints(const stereograsp::arm_cmd_t& command, ArmTarget target) const;

  ArmGeometry geometry_;
  std::map<std::string, int64_t> last_sequence_;  ///< per sender
};

}  // namespace sg::arm
