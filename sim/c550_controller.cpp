#include "sim/c550_controller.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "arm_driver/aci.hpp"
#include "arm_driver/units.hpp"

namespace sg::sim {
namespace {

constexpr double kNever = -std::numeric_limits<double>::infinity();

std::string format(const char* pattern, double a, double b = 0, double c = 0) {
  char text[160];
  std::snprintf(text, sizeof text, pattern, a, b, c);
  return text;
}

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("C550Params: " + what);
}

void check_params(const C550Params& p, const arm::ArmGeometry& geometry) {
  require(p.delay_min >= 0 && p.delay_min <= p.delay_max && std::isfinite(p.delay_max),
          format("delays %g..%g s: need 0 <= delay_min <= delay_max", p.delay_min, p.delay_max));
  require(p.speed_percent >= 1 && p.speed_percent <= 100,
          "speed_percent " + std::to_string(p.speed_percent) + " is outside 1..100");
  require(p.gripper_time >= 0 && std::isfinite(p.gripper_time),
          format("gripper_time %g s must be finite and >= 0", p.gripper_time));
  require(p.gripper_closed_width >= 0 && p.gripper_open_width > p.gripper_closed_width,
          format("gripper widths closed %g m, open %g m: need 0 <= closed < open",
                 p.gripper_closed_width, p.gripper_open_width));
  require(p.grasp_tolerance >= 0 && p.ball_radius > 0,
          format("grasp_tolerance %g m and ball_radius %g m must be >= 0 and > 0",
                 p.grasp_tolerance, p.ball_radius));
  require(!p.start_holding || 2 * p.ball_radius < p.gripper_open_width,
          format("start_holding: the ball (%g m across) does not fit the open gripper (%g m)",
                 2 * p.ball_radius, p.gripper_open_width));
  require(p.ready.allFinite() && arm::within_limits(geometry, p.ready),
          "the ready joints are outside the arm's joint limits");
}

/// `*** 73 JOINT LIMIT: ...` for the first joint of `q` that is not finite or out of limits.
std::string joint_limit_error(const arm::ArmGeometry& geometry, const arm::Joints& q) {
  for (int i = 0; i < 6; ++i) {
    const arm::DhLink& link = geometry.links[static_cast<size_t>(i)];
    const std::string joint = "*** 73 JOINT LIMIT: joint " + std::to_string(i + 1);
    if (!std::isfinite(q[i])) return joint + " is not finite";
    if (q[i] < link.min || q[i] > link.max) {
      return joint + format(" at %.4f deg is outside %.1f..%.1f deg", arm::to_degrees(q[i]),
                            arm::to_degrees(link.min), arm::to_degrees(link.max));
    }
  }
  return "";
}

}  // namespace

C550Controller::C550Controller(arm::ArmGeometry geometry, C550Params params)
    : geometry_(std::move(geometry)),
      params_(std::move(params)),
      speed_percent_(params_.speed_percent),
      rng_(params_.seed) {
  check_params(params_, geometry_);
  motion_ = {params_.ready, params_.ready, kNever, kNever};
  const double width = params_.start_holding
                           ? std::max(2 * params_.ball_radius, params_.gripper_closed_width)
                           : params_.gripper_open_width;
  stroke_ = {width, width, kNever, kNever};
  holding_ = params_.start_holding;
  last_command_time_ = kNever;
}

void C550Controller::advance(double t) {
  if (t >= motion_.end) motion_ = {motion_.to, motion_.to, motion_.end, motion_.end};
  if (t >= stroke_.end) stroke_ = {stroke_.to, stroke_.to, stroke_.end, stroke_.end};
}

arm::Joints C550Controller::joints(double t) const {
  if (t >= motion_.end) return motion_.to;
  if (t <= motion_.start) return motion_.from;
  const double s = (t - motion_.start) / (motion_.end - motion_.start);
  return motion_.from + s * (motion_.to - motion_.from);
}

Eigen::Isometry3d C550Controller::tool_pose(double t) const {
  return arm::forward_kinematics(geometry_, joints(t));
}

double C550Controller::gripper_opening(double t) const {
  if (t >= stroke_.end) return stroke_.to;
  if (t <= stroke_.start) return stroke_.from;
  const double s = (t - stroke_.start) / (stroke_.end - stroke_.start);
  return stroke_.from + s * (stroke_.to - stroke_.from);
}

double C550Controller::settle_time() const { return std::max(motion_.end, stroke_.end); }

CommandResult C550Controller::set_speed(int percent) {
  if (percent < 1 || percent > 100) {
    return {"*** 10 SPEED " + std::to_string(percent) + " is outside 1..100"};
  }
  speed_percent_ = percent;
  return {};
}

CommandResult C550Controller::move_joints(const arm::Joints& target, double t) {
  check_time(t, "move_joints");
  if (std::string error = joint_limit_error(geometry_, target); !error.empty()) return {error};
  start_motion(target, t);
  return {};
}

CommandResult C550Controller::move_pose(const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy,
                                        double t) {
  check_time(t, "move_pose");
  const arm::IkResult ik =
      arm::solve_nearest(geometry_, arm::pose_from_xyz_rpy(xyz, rpy), joints(t));
  if (!ik.joints) return {"*** 72 LOCATION OUT OF RANGE: " + ik.error};
  return move_joints(*ik.joints, t);
}

CommandResult C550Controller::ready(double t) { return move_joints(params_.ready, t); }

void C550Controller::abort(double t) {
  check_time(t, "abort");
  const arm::Joints here = joints(t);
  motion_ = {here, here, t, t};
}

void C550Controller::open(double t) {
  check_time(t, "open");
  if (holding_) released_at_ = tool_pose(t).translation();
  holding_ = false;
  start_stroke(params_.gripper_open_width, t);
}

void C550Controller::close(double t, const std::optional<Eigen::Vector3d>& ball_centre) {
  check_time(t, "close");
  const double ball_width = 2 * params_.ball_radius;
  const bool near = ball_centre && ball_centre->allFinite() &&
                    (tool_pose(t).translation() - *ball_centre).norm() <= params_.grasp_tolerance;
  if (!holding_ && near && gripper_opening(t) > ball_width) holding_ = true;
  closes_.push_back({t, tool_pose(t).translation(), ball_centre, holding_});
  start_stroke(
      holding_ ? std::max(ball_width, params_.gripper_closed_width) : params_.gripper_closed_width,
      t);
}

double C550Controller::interaction_delay() {
  // Drawn from the raw 32-bit output (fixed by the standard), not uniform_real_distribution
  // (whose algorithm differs between standard libraries), so a seed gives the same delays
  // everywhere.
  const double u = static_cast<double>(rng_()) / 4294967296.0;  // [0, 1)
  return params_.delay_min + u * (params_.delay_max - params_.delay_min);
}

void C550Controller::check_time(double t, const char* command) {
  if (!std::isfinite(t) || t < last_command_time_) {
    throw std::invalid_argument(
        std::string("C550Controller::") + command + ": time " +
        format("%.6f s is before the last command (%.6f s) or not finite", t, last_command_time_));
  }
  last_command_time_ = t;
  advance(t);
}

void C550Controller::start_motion(const arm::Joints& target, double t) {
  const arm::Joints here = joints(t);
  const double duration = arm::motion_time(geometry_, here, target, speed_percent_ / 100.0);
  motion_ = {here, target, t, t + duration};
}

void C550Controller::start_stroke(double width, double t) {
  const double from = gripper_opening(t);
  const double full = params_.gripper_open_width - params_.gripper_closed_width;
  stroke_ = {from, width, t, t + std::abs(width - from) / full * params_.gripper_time};
}

std::string C550Controller::memory_access_error(uint8_t memtype, uint16_t segment, uint16_t offset,
                                                int length, bool write) const {
  const std::string where = "memory type " + arm::aci::byte_name(memtype) + " at " +
                            std::to_string(segment) + ":" + std::to_string(offset) + ", " +
                            std::to_string(length) + " bytes: ";
  if (length < 1) return where + "no bytes";
  switch (memtype) {
    case arm::aci::kMemSegment:
      if (offset + length > kSegmentSize) return where + "runs past the 64 KiB segment";
      return "";
    case arm::aci::kMemPointerList:
      if (write) return where + "the RAPL pointer list is read-only";
      if (offset + length > 4 * kPointerCount) {
        return where + "runs past the " + std::to_string(kPointerCount) + "-pointer list";
      }
      return "";
    case arm::aci::kMemSession:
      if (write) return where + "the session byte is read-only";
      if (length != 1) return where + "the session byte is read as 1 byte";
      return "";
    default:
      return where + "not a memory type the emulator models (0x00, 0x40, 0x48)";
  }
}

std::vector<uint8_t> C550Controller::read_memory(uint8_t memtype, uint16_t segment, uint16_t offset,
                                                 int length) const {
  if (std::string error = memory_access_error(memtype, segment, offset, length, false);
      !error.empty()) {
    throw std::invalid_argument("read " + error);
  }
  if (memtype == arm::aci::kMemSession) return {0x01};
  if (memtype == arm::aci::kMemPointerList) {
    const auto list = pointer_list();
    return {list.begin() + offset, list.begin() + offset + length};
  }
  const auto found = segments_.find(segment);
  if (found == segments_.end()) return std::vector<uint8_t>(static_cast<size_t>(length), 0);
  return {found->second.begin() + offset, found->second.begin() + offset + length};
}

void C550Controller::write_memory(uint8_t memtype, uint16_t segment, uint16_t offset,
                                  std::span<const uint8_t> data) {
  const int length = static_cast<int>(data.size());
  if (std::string error = memory_access_error(memtype, segment, offset, length, true);
      !error.empty()) {
    throw std::invalid_argument("write " + error);
  }
  std::vector<uint8_t>& memory = segments_[segment];
  if (memory.empty()) memory.assign(kSegmentSize, 0);
  std::copy(data.begin(), data.end(), memory.begin() + offset);
}

std::array<uint8_t, 4 * C550Controller::kPointerCount> C550Controller::pointer_list() const {
  // Made-up but fixed addresses: the real list's contents are not public.
  std::array<uint8_t, 4 * kPointerCount> bytes{};
  for (int i = 0; i < kPointerCount; ++i) {
    const uint32_t pointer = 0x00020000u + 0x100u * static_cast<uint32_t>(i);
    for (int b = 0; b < 4; ++b) bytes[static_cast<size_t>(4 * i + b)] = (pointer >> (8 * b)) & 0xFF;
  }
  return bytes;
}

}  // namespace sg::sim
