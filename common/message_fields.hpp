#pragma once

/// Every field of every stereograsp message, named, in its .lcm order: one list that tools which
/// treat fields alike share (sg-report's CSV columns, the tests' field dumps). Add a type's fields
/// here when adding a .lcm file, beside common/message_types.hpp.
///
///     struct Printer {
///       template <class T> void add(const std::string& name, const T& value) { ... }
///     };
///     Printer p;
///     sg::visit_fields(point, p);   // add("utime", ...), add("visible", ...), add("position",
///     ...)

#include <concepts>
#include <string>
#include <type_traits>

#include "common/message_types.hpp"

namespace sg {

// clang-format off
/// Each type's fields in their .lcm order, for a visitor with
/// `template <class T> void add(const std::string& name, T& value)` (T const for a const message,
/// so the same list reads and fills).
#define SG_FIELD(f) v.add(#f, m.f)

template <class M, class V>
  requires std::same_as<std::remove_const_t<M>, stereograsp::image_t>
void visit_fields(M& m, V& v) {
  SG_FIELD(utime); SG_FIELD(camera); SG_FIELD(frame_number); SG_FIELD(width); SG_FIELD(height);
  SG_FIELD(row_stride); SG_FIELD(pixel_format); SG_FIELD(size); SG_FIELD(data);
}
template <class M, class V>
  requires std::same_as<std::remove_const_t<M>, stereograsp::blob_t>
void visit_fields(M& m, V& v) {
  SG_FIELD(utime); SG_FIELD(camera); SG_FIELD(frame_number); SG_FIELD(found); SG_FIELD(mode);
  SG_FIELD(centroid); SG_FIELD(area); SG_FIELD(major_axis); SG_FIELD(minor_axis);
  SG_FIELD(orientation); SG_FIELD(major_axis_ends); SG_FIELD(minor_axis_ends);
  SG_FIELD(bounding_box); SG_FIELD(search_window); SG_FIELD(num_regions); SG_FIELD(misses);
  SG_FIELD(centre); SG_FIELD(radius); SG_FIELD(fit_support); SG_FIELD(fit_arc);
  SG_FIELD(confidence); SG_FIELD(candidates);
}
template <class M, class V>
  requires std::same_as<std::remove_const_t<M>, stereograsp::point3_t>
void visit_fields(M& m, V& v) {
  SG_FIELD(utime); SG_FIELD(visible); SG_FIELD(position); SG_FIELD(position_sigma);
  SG_FIELD(reprojection_error); SG_FIELD(seen_by); SG_FIELD(flags);
}
template <class M, class V>
  requires std::same_as<std::remove_const_t<M>, stereograsp::trajectory_t>
void visit_fields(M& m, V& v) {
  SG_FIELD(utime); SG_FIELD(source_utime); SG_FIELD(start_utime); SG_FIELD(period_us);
  SG_FIELD(num_points); SG_FIELD(position); SG_FIELD(position_sigma);
  SG_FIELD(occluded_samples); SG_FIELD(status); SG_FIELD(model); SG_FIELD(model_order);
}
template <class M, class V>
  requires std::same_as<std::remove_const_t<M>, stereograsp::arm_cmd_t>
void visit_fields(M& m, V& v) {
  SG_FIELD(utime); SG_FIELD(source_utime); SG_FIELD(target_utime); SG_FIELD(sequence);
  SG_FIELD(mode); SG_FIELD(position); SG_FIELD(orientation); SG_FIELD(joints); SG_FIELD(gripper);
  SG_FIELD(speed); SG_FIELD(take_over); SG_FIELD(sender); SG_FIELD(auth_counter);
  SG_FIELD(auth_tag);
}
template <class M, class V>
  requires std::same_as<std::remove_const_t<M>, stereograsp::arm_status_t>
void visit_fields(M& m, V& v) {
  SG_FIELD(utime); SG_FIELD(state); SG_FIELD(joints); SG_FIELD(tool_position);
  SG_FIELD(tool_orientation); SG_FIELD(gripper); SG_FIELD(last_received_sequence);
  SG_FIELD(last_executed_sequence); SG_FIELD(last_rejected_sequence); SG_FIELD(rejection_reason);
  SG_FIELD(source_utime); SG_FIELD(interaction_time); SG_FIELD(speed); SG_FIELD(error);
  SG_FIELD(commander); SG_FIELD(driver_start_utime); SG_FIELD(watchdog);
}
template <class M, class V>
  requires std::same_as<std::remove_const_t<M>, stereograsp::grasp_command_t>
void visit_fields(M& m, V& v) {
  SG_FIELD(utime); SG_FIELD(sequence); SG_FIELD(command); SG_FIELD(standoff); SG_FIELD(sender);
  SG_FIELD(auth_counter); SG_FIELD(auth_tag);
}
template <class M, class V>
  requires std::same_as<std::remove_const_t<M>, stereograsp::grasp_status_t>
void visit_fields(M& m, V& v) {
  SG_FIELD(utime); SG_FIELD(source_utime); SG_FIELD(state); SG_FIELD(activity);
  SG_FIELD(last_action); SG_FIELD(target); SG_FIELD(target_utime); SG_FIELD(outcome);
  SG_FIELD(message); SG_FIELD(command_sequence); SG_FIELD(command_result);
  SG_FIELD(command_reason);
}
template <class M, class V>
  requires std::same_as<std::remove_const_t<M>, stereograsp::sim_arm_state_t>
void visit_fields(M& m, V& v) {
  SG_FIELD(utime); SG_FIELD(joints); SG_FIELD(tool_position); SG_FIELD(tool_orientation);
  SG_FIELD(gripper_opening); SG_FIELD(holding_object);
}
template <class M, class V>
  requires std::same_as<std::remove_const_t<M>, stereograsp::process_status_t>
void visit_fields(M& m, V& v) {
  SG_FIELD(utime); SG_FIELD(process); SG_FIELD(host); SG_FIELD(pid);
  SG_FIELD(messages_received); SG_FIELD(decode_errors); SG_FIELD(handler_errors);
  SG_FIELD(refused_inputs); SG_FIELD(publish_errors); SG_FIELD(last_problem); SG_FIELD(state);
  SG_FIELD(state_detail); SG_FIELD(start_utime); SG_FIELD(num_channels); SG_FIELD(channel);
  SG_FIELD(messages_in); SG_FIELD(messages_out); SG_FIELD(rate_in_hz); SG_FIELD(rate_out_hz);
  SG_FIELD(num_peers); SG_FIELD(peer); SG_FIELD(peer_utime); SG_FIELD(peer_recv_utime);
  SG_FIELD(peer_offset_us); SG_FIELD(peer_offset_error_us);
  SG_FIELD(unvouched_inputs); SG_FIELD(num_unvouched); SG_FIELD(unvouched_channel);
  SG_FIELD(unvouched_sender); SG_FIELD(unvouched_verdict); SG_FIELD(unvouched_count);
  SG_FIELD(vouched_as);
}

// clang-format on
#undef SG_FIELD

}  // namespace sg
