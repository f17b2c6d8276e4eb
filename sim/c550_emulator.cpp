#include "sim/c550_emulator.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <set>
#include <stdexcept>
#include <utility>

#include "arm_driver/units.hpp"

namespace sg::sim {
namespace {

namespace aci = arm::aci;
namespace rapl = arm::rapl;

/// Retries of one block before a host read is abandoned (docs/arm.md: 3 tries).
constexpr int kBlockTries = 3;
/// A silence longer than this inside a header or block abandons it (an inter-character time-out:
/// at 38,400 baud a frame's bytes are 0.26 ms apart, and the host waits 200 ms for an answer).
constexpr double kFrameGap = 0.1;

std::string trim(std::string_view text) {
  const size_t begin = text.find_first_not_of(" \t");
  if (begin == std::string_view::npos) return "";
  const size_t end = text.find_last_not_of(" \t");
  return std::string(text.substr(begin, end - begin + 1));
}

/// Exactly `count` numbers, or RaplError naming what was expected.
std::vector<double> numbers(const std::string& rest, size_t count, const char* what) {
  std::vector<double> values = rapl::parse_numbers(rest);
  if (values.size() != count) {
    throw rapl::RaplError("expected " + std::to_string(count) + " numbers (" + what + "), got " +
                          std::to_string(values.size()));
  }
  return values;
}

int integer(double value, const char* what) {
  if (value != std::floor(value) || std::abs(value) > 1e6) {
    throw rapl::RaplError(std::string(what) + " must be a whole number");
  }
  return static_cast<int>(value);
}

void no_arguments(const std::string& rest) {
  if (!rest.empty()) throw rapl::RaplError("takes no arguments, got '" + rest + "'");
}

/// OPEN and CLOSE take an optional force (RobWork sends one); the model ignores it.
void grip_argument(const std::string& rest) {
  if (!rest.empty()) numbers(rest, 1, "grip force, ignored");
}

bool valid_name(const std::string& name) {
  return !name.empty() && std::isalpha(static_cast<unsigned char>(name.front())) &&
         std::all_of(name.begin(), name.end(), [](char c) {
           return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
         });
}

}  // namespace

C550Emulator::C550Emulator(C550Controller& controller, int slave)
    : controller_(controller), slave_(slave) {
  if (slave < 1 || slave > 127) {
    throw std::invalid_argument("C550Emulator: slave number " + std::to_string(slave) +
                                " is outside 1..127");
  }
}

void C550Emulator::feed(uint8_t byte, double t) {
  input_.push_back({byte, t});
  pump(t);
}

std::vector<uint8_t> C550Emulator::take_output(double t) {
  std::vector<uint8_t> bytes;
  for (const Chunk& chunk : take_output_chunks(t)) {
    bytes.insert(bytes.end(), chunk.bytes.begin(), chunk.bytes.end());
  }
  return bytes;
}

std::vector<C550Emulator::Chunk> C550Emulator::take_output_chunks(double t) {
  pump(t);
  std::vector<Chunk> chunks;
  while (!output_.empty() && output_.front().due <= t) {
    chunks.push_back(std::move(output_.front().chunk));
    output_.pop_front();
  }
  return chunks;
}

double C550Emulator::next_output_time() const {
  if (!output_.empty()) return output_.front().due;
  return deferred_ ? deferred_->due : std::numeric_limits<double>::infinity();
}

std::vector<std::string> C550Emulator::take_events() { return std::exchange(events_, {}); }

void C550Emulator::pump(double now) {
  // Bytes that arrived while a reply was held are handled once it has gone, in order; a byte
  // handled here may defer a reply that is already due, which goes before the next byte
  // (fuzz/c550_emulator_fuzz: it was left queued, due in the past).
  run_deferred(now);
  while (!input_.empty() && hold_until_ <= now) {
    const Input in = input_.front();
    input_.pop_front();
    process(in.byte, std::max(in.t, hold_until_));
    run_deferred(now);
  }
}

void C550Emulator::process(uint8_t byte, double t) {
  if (mode_ == Mode::kAci) {
    aci_byte(byte, t);
  } else {
    rapl_byte(byte, t);
  }
}

void C550Emulator::emit(std::vector<uint8_t> bytes, double due, bool ack) {
  output_.push_back({due, {std::move(bytes), ack}});
}

void C550Emulator::event(std::string text) { events_.push_back(std::move(text)); }

// ---- ACI ----

void C550Emulator::aci_byte(uint8_t byte, double t) {
  const bool in_frame = aci_ == Aci::kHeader || (aci_ == Aci::kReceiving && !frame_.empty());
  if (in_frame && t - last_aci_byte_ > kFrameGap) {
    event("ACI: " + std::to_string(frame_.size()) + " bytes of a " +
          (aci_ == Aci::kHeader ? "header" : "block") + " abandoned after a silence");
    if (aci_ == Aci::kHeader) to_idle();
    frame_.clear();
  }
  last_aci_byte_ = t;
  switch (aci_) {
    case Aci::kHeader:
      header_byte(byte, t);
      return;
    case Aci::kSending:
      sending_byte(byte, t);
      return;
    case Aci::kReceiving:
      receiving_byte(byte, t);
      return;
    case Aci::kAwaitEot:
      if (byte == aci::EOT || (byte == rapl::CTRL_C && header_.memtype == aci::kMemSession)) {
        const bool session = header_.memtype == aci::kMemSession;
        to_idle();
        if (session) mode_ = Mode::kRapl;
        if (byte == rapl::CTRL_C) rapl_byte(byte, t);
        return;
      }
      aci_restart(byte, t);
      return;
    case Aci::kIdle:
      aci_restart(byte, t);
      return;
  }
}

void C550Emulator::aci_restart(uint8_t byte, double t) {
  if (byte == aci::SOH) {
    to_idle();
    frame_ = {aci::SOH};
    aci_ = Aci::kHeader;
    return;
  }
  recent_.push_back(byte);
  if (recent_.size() > 3) recent_.erase(recent_.begin());
  const auto enquiry = aci::encode_enquiry(slave_);
  if (!std::equal(recent_.begin(), recent_.end(), enquiry.begin(), enquiry.end())) return;
  if (aci_ != Aci::kIdle) event("enquiry in the middle of a transfer: transfer abandoned");
  to_idle();
  const auto reply = aci::encode_enquiry_reply(slave_);
  emit({reply[0], reply[1]}, t);
  emit({reply[2]}, t, true);
}

void C550Emulator::header_byte(uint8_t byte, double t) {
  frame_.push_back(byte);
  if (frame_.size() < aci::kHeaderSize) return;
  std::string refusal;
  aci::AciHeader header;
  try {
    header = aci::decode_header(frame_);
    if (header.slave != slave_) {
      refusal = "header for slave " + std::to_string(header.slave);
    } else {
      refusal = controller_.memory_access_error(header.memtype, header.segment, header.offset,
                                                header.length, header.write);
    }
  } catch (const aci::AciError& e) {
    refusal = e.what();
  }
  if (!refusal.empty()) {
    event("ACI header NAKed: " + refusal);
    to_idle();
    emit({aci::NAK}, t);
    return;
  }
  accept_header(header, t);
}

void C550Emulator::accept_header(const aci::AciHeader& header, double t) {
  to_idle();
  header_ = header;
  emit({aci::ACK}, t, true);
  if (header.write) {
    aci_ = Aci::kReceiving;
    return;
  }
  blocks_ = aci::encode_blocks(
      controller_.read_memory(header.memtype, header.segment, header.offset, header.length));
  aci_ = Aci::kSending;
  send_block(t);
}

void C550Emulator::send_block(double t) {
  emit(blocks_[static_cast<size_t>(block_)], t);
  ++tries_;
}

void C550Emulator::sending_byte(uint8_t byte, double t) {
  if (byte == aci::ACK) {
    ++block_;
    tries_ = 0;
    if (block_ < static_cast<int>(blocks_.size())) {
      send_block(t);
    } else {
      emit({aci::EOT}, t);
      aci_ = Aci::kAwaitEot;
    }
  } else if (byte == aci::NAK) {
    if (tries_ < kBlockTries) {
      send_block(t);
      return;
    }
    event("ACI read: block " + std::to_string(block_ + 1) + " NAKed " +
          std::to_string(kBlockTries) + " times; transfer abandoned");
    to_idle();
  } else {
    aci_restart(byte, t);
  }
}

void C550Emulator::receiving_byte(uint8_t byte, double t) {
  const aci::BlockLayout layout = aci::block_layout(header_.length);
  const int total = layout.total_blocks();
  if (!frame_.empty()) {
    frame_.push_back(byte);
    const int index = std::min(block_, total - 1);
    const int size = index == layout.full_blocks ? layout.last_size : aci::kBlockSize;
    if (static_cast<int>(frame_.size()) == aci::block_frame_size(size)) finish_received_block(t);
  } else if (byte == aci::STX) {
    frame_.push_back(byte);  // a new block, or the last one again if our ACK was lost
  } else if (byte == aci::EOT) {
    if (block_ == total) {
      std::vector<uint8_t> data;
      for (const auto& block : blocks_) data.insert(data.end(), block.begin(), block.end());
      controller_.write_memory(header_.memtype, header_.segment, header_.offset, data);
    } else {
      event("ACI write: EOT after " + std::to_string(block_) + " of " + std::to_string(total) +
            " blocks; transfer abandoned");
    }
    to_idle();
  } else {
    aci_restart(byte, t);
  }
}

void C550Emulator::finish_received_block(double t) {
  const aci::BlockLayout layout = aci::block_layout(header_.length);
  const int index = std::min(block_, layout.total_blocks() - 1);
  const bool last = index == layout.full_blocks;
  const std::vector<uint8_t> frame = std::exchange(frame_, {});
  try {
    aci::Block block = aci::decode_block(frame);
    if (block.last != last) {
      throw aci::AciError(std::string("ends with ") + (block.last ? "ETX" : "ETB") +
                          (last ? ", expected ETX" : ", expected ETB"));
    }
    if (block_ < layout.total_blocks()) {
      blocks_.push_back(std::move(block.data));
      ++block_;
    }
    emit({aci::ACK}, t, true);
  } catch (const aci::AciError& e) {
    event("ACI write: block " + std::to_string(index + 1) + " NAKed: " + e.what());
    emit({aci::NAK}, t);
  }
}

void C550Emulator::to_idle() {
  aci_ = Aci::kIdle;
  frame_.clear();
  recent_.clear();
  blocks_.clear();
  block_ = 0;
  tries_ = 0;
}

// ---- RAPL ----

void C550Emulator::rapl_byte(uint8_t byte, double t) {
  if (byte == rapl::XON || byte == rapl::XOFF) return;
  if (byte == rapl::CTRL_Z) {
    if (help_given_ && ++ctrl_z_ == 2) {
      mode_ = Mode::kAci;
      to_idle();
      help_given_ = false;
      ctrl_z_ = 0;
      line_.clear();
      line_length_ = 0;
    }
    return;
  }
  ctrl_z_ = 0;
  if (byte == rapl::CTRL_C) {
    line_.clear();
    line_length_ = 0;
    emit({rapl::kPrompt.begin(), rapl::kPrompt.end()}, t);
  } else if (byte == rapl::CR) {
    end_line(t);
  } else if (byte >= 0x20 && byte <= 0x7E) {
    emit({byte}, t);
    ++line_length_;
    if (line_.size() < rapl::kMaxLine) line_.push_back(static_cast<char>(byte));
  }
}

void C550Emulator::end_line(double t) {
  const std::string line = std::exchange(line_, {});
  const size_t length = std::exchange(line_length_, 0);
  if (length <= rapl::kMaxLine && acts_after_delay(line)) {
    // The controller digests a motion command for the interaction delay, then acts and answers.
    executed_.push_back(line);
    deferred_ = Deferred{line, t + controller_.interaction_delay()};
    hold_until_ = std::max(hold_until_, deferred_->due);
    return;
  }
  Answer answer;
  if (length > rapl::kMaxLine) {
    executed_.push_back(line + "...");
    answer.lines = {"*** 10 LINE TOO LONG: " + std::to_string(length) + " characters, at most " +
                    std::to_string(rapl::kMaxLine)};
  } else if (!trim(line).empty()) {
    executed_.push_back(line);
    answer = execute(line, t);
  }
  reply(line, answer, t);
}

bool C550Emulator::acts_after_delay(const std::string& line) {
  static const std::set<std::string> kMotion = {"MA", "MOVE", "READY", "OPEN", "CLOSE", "JOINT"};
  return kMotion.contains(rapl::split_command(line).verb);
}

void C550Emulator::run_deferred(double now) {
  if (!deferred_ || deferred_->due > now) return;
  const Deferred d = *std::exchange(deferred_, std::nullopt);
  reply(d.line, execute(d.line, d.due), d.due);
}

void C550Emulator::reply(const std::string& line, const Answer& answer, double t) {
  for (const std::string& text : answer.lines) {
    if (text.starts_with("***")) event("'" + line + "': " + text);
  }
  const double due = std::max(t, answer.due.value_or(t));
  emit({rapl::ACK}, due, true);
  std::string text;
  for (const std::string& line_text : answer.lines) text += "\r\n" + line_text;
  text += rapl::kPrompt;
  emit({text.begin(), text.end()}, due);
  hold_until_ = std::max(hold_until_, due);
}

C550Emulator::Answer C550Emulator::execute(const std::string& line, double t) {
  using Handler = Answer (C550Emulator::*)(const std::string& rest, double t);
  static const std::map<std::string, Handler> kCommands = {
      {"SPEED", &C550Emulator::speed},      {"MA", &C550Emulator::move_absolute},
      {"W2", &C550Emulator::where},         {"POINT", &C550Emulator::point},
      {"MOVE", &C550Emulator::move},        {"LLOC", &C550Emulator::lloc},
      {"JOINT", &C550Emulator::joint},      {"OPEN", &C550Emulator::open},
      {"CLOSE", &C550Emulator::close},      {"READY", &C550Emulator::ready},
      {"ABORT", &C550Emulator::abort},      {"FINISH", &C550Emulator::finish},
      {"NOH", &C550Emulator::no_operation}, {"HELP", &C550Emulator::help}};
  const rapl::CommandLine command = rapl::split_command(line);
  help_given_ = false;
  const auto found = kCommands.find(command.verb);
  if (found == kCommands.end()) return {{"*** 10 UNKNOWN COMMAND '" + command.verb + "'"}, {}};
  try {
    return (this->*found->second)(trim(command.rest), t);
  } catch (const rapl::RaplError& e) {
    return {{"*** 10 " + command.verb + ": " + e.what()}, {}};
  }
}

C550Emulator::Answer C550Emulator::speed(const std::string& rest, double /*t*/) {
  const CommandResult result =
      controller_.set_speed(integer(numbers(rest, 1, "percent").front(), "SPEED"));
  return {result ? std::vector<std::string>{} : std::vector{result.error}, {}};
}

C550Emulator::Answer C550Emulator::move_absolute(const std::string& rest, double t) {
  const std::vector<double> degrees = numbers(rest, 6, "joints, degrees");
  arm::Joints q;
  for (int i = 0; i < 6; ++i) q[i] = arm::from_degrees(degrees[static_cast<size_t>(i)]);
  return motion(controller_.move_joints(q, t), t);
}

C550Emulator::Answer C550Emulator::where(const std::string& rest, double t) {
  no_arguments(rest);
  const arm::Joints q = controller_.joints(t);
  return {{rapl::format_joints_reply({q[0], q[1], q[2], q[3], q[4], q[5]})}, {}};
}

C550Emulator::Answer C550Emulator::open(const std::string& rest, double t) {
  grip_argument(rest);
  controller_.open(t);
  return motion({}, t);
}

C550Emulator::Answer C550Emulator::close(const std::string& rest, double t) {
  grip_argument(rest);
  controller_.close(t, ball_);
  const Eigen::Vector3d tcp = controller_.tool_pose(t).translation();
  char text[160];
  if (ball_) {
    std::snprintf(text, sizeof text,
                  "CLOSE at (%.3f, %.3f, %.3f): the ball's centre %.1f mm away: %s", tcp.x(),
                  tcp.y(), tcp.z(), (tcp - *ball_).norm() * 1e3,
                  controller_.holding() ? "held" : "not held");
  } else {
    std::snprintf(text, sizeof text, "CLOSE at (%.3f, %.3f, %.3f): no ball known", tcp.x(), tcp.y(),
                  tcp.z());
  }
  event(text);
  return motion({}, t);
}

C550Emulator::Answer C550Emulator::ready(const std::string& rest, double t) {
  no_arguments(rest);
  return motion(controller_.ready(t), t);
}

C550Emulator::Answer C550Emulator::abort(const std::string& rest, double t) {
  no_arguments(rest);
  controller_.abort(t);
  return {};
}

C550Emulator::Answer C550Emulator::finish(const std::string& rest, double /*t*/) {
  no_arguments(rest);
  return {{}, controller_.settle_time()};
}

C550Emulator::Answer C550Emulator::no_operation(const std::string& rest, double /*t*/) {
  no_arguments(rest);
  return {};
}

C550Emulator::Answer C550Emulator::help(const std::string& rest, double /*t*/) {
  no_arguments(rest);
  help_given_ = true;
  return {};
}

C550Emulator::Answer C550Emulator::motion(const CommandResult& result, double /*t*/) {
  if (!result) return {{result.error}, {}};
  return {};
}

C550Emulator::Answer C550Emulator::point(const std::string& rest, double /*t*/) {
  const size_t end = rest.find_first_of(" ,\t");
  const std::string name = rest.substr(0, end);
  if (!valid_name(name)) {
    throw rapl::RaplError("'" + name +
                          "' is not a location name (a letter, then letters, digits, _)");
  }
  const std::vector<double> values =
      numbers(end == std::string::npos ? "" : rest.substr(end), 6, "x,y,z inches, r,p,y degrees");
  rapl::Location location;
  location.name = name;
  for (int i = 0; i < 3; ++i) {
    location.xyz[i] = arm::from_inches(values[static_cast<size_t>(i)]);
    location.rpy[i] = arm::from_degrees(values[static_cast<size_t>(3 + i)]);
  }
  locations_[name] = location;
  return {};
}

C550Emulator::Answer C550Emulator::move(const std::string& rest, double t) {
  const auto found = locations_.find(rest);
  if (found == locations_.end())
    return {{"*** 10 MOVE: location '" + rest + "' is not defined"}, {}};
  return motion(controller_.move_pose(found->second.xyz, found->second.rpy, t), t);
}

C550Emulator::Answer C550Emulator::lloc(const std::string& rest, double /*t*/) {
  const auto found = locations_.find(rest);
  if (found == locations_.end())
    return {{"*** 10 LLOC: location '" + rest + "' is not defined"}, {}};
  return {{rapl::format_location_reply(found->second)}, {}};
}

C550Emulator::Answer C550Emulator::joint(const std::string& rest, double t) {
  const std::vector<double> values = numbers(rest, 2, "joint 1..6, degrees");
  const int index = integer(values[0], "the joint number");
  if (index < 1 || index > 6)
    throw rapl::RaplError("joint " + std::to_string(index) + " is outside 1..6");
  arm::Joints q = controller_.joints(t);
  q[index - 1] += arm::from_degrees(values[1]);
  return motion(controller_.move_joints(q, t), t);
}

}  // namespace sg::sim
