#include "arm_driver/rapl.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>

#include "arm_driver/units.hpp"

namespace sg::arm::rapl {

std::string printable(std::string_view text) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte >= 0x20 && byte <= 0x7e) {
      out += c;
    } else {
      out += "\\x";
      out += kHex[byte >> 4];
      out += kHex[byte & 0xf];
    }
  }
  return out;
}

namespace {

std::string fixed4(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4f", value);
  if (std::string_view(text) == "-0.0000") return "0.0000";  // a rounding artefact, not a sign
  return text;
}

std::string join(const std::vector<double>& values, const char* separator) {
  std::string out;
  for (size_t i = 0; i < values.size(); ++i) {
    if (i) out += separator;
    out += fixed4(values[i]);
  }
  return out;
}

bool is_separator(char c) { return c == ',' || c == ' ' || c == '\t'; }

}  // namespace

std::string speed(int percent) {
  if (percent < 1 || percent > 100) {
    throw RaplError("SPEED " + std::to_string(percent) + " is outside 1..100");
  }
  return "SPEED " + std::to_string(percent);
}

std::string move_joints(const JointArray& radians) {
  std::vector<double> degrees;
  for (double q : radians) {
    if (!std::isfinite(q)) throw RaplError("MA with a joint that is not finite");
    degrees.push_back(to_degrees(q));
  }
  return "MA " + join(degrees, ",");
}

std::string point(const std::string& name, const Eigen::Vector3d& xyz_metres,
                  const Eigen::Vector3d& rpy_radians) {
  std::vector<double> values;
  for (int i = 0; i < 3; ++i) values.push_back(to_inches(xyz_metres[i]));
  for (int i = 0; i < 3; ++i) values.push_back(to_degrees(rpy_radians[i]));
  return "POINT " + name + " " + join(values, ",");
}

std::string move(const std::string& name) { return "MOVE " + name; }
std::string lloc(const std::string& name) { return "LLOC " + name; }

void ReplyReader::feed(uint8_t byte) {
  if (byte == XON || byte == XOFF) return;
  if (complete_) throw RaplError("byte " + std::to_string(byte) + " after the prompt");
  if (!acknowledged_) {
    if (byte == CR || byte == LF) return;  // a controller that echoes the CR: tolerated
    if (byte != ACK) {
      throw RaplError("expected ACK after the command, got byte " + std::to_string(byte));
    }
    acknowledged_ = true;
    return;
  }
  text_.push_back(static_cast<char>(byte));
  if (text_.size() > 4096) throw RaplError("reply longer than 4096 bytes without a prompt");
  if (text_.ends_with(kPrompt)) complete_ = true;
}

Reply ReplyReader::reply() const {
  if (!complete_) throw RaplError("reply read before its prompt");
  return parse_reply_text(std::string_view(text_).substr(0, text_.size() - kPrompt.size()));
}

void ReplyReader::reset() { *this = ReplyReader(); }

Reply parse_reply_text(std::string_view text) {
  Reply reply;
  size_t start = 0;
  while (start <= text.size()) {
    size_t end = text.find_first_of("\r\n", start);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = text.substr(start, end - start);
    if (!line.empty()) {
      reply.lines.emplace_back(line);
      if (line.starts_with("***") && !reply.error) reply.error = std::string(line);
    }
    start = end + 1;
  }
  return reply;
}

JointArray parse_joints(const Reply& reply) {
  for (const std::string& line : reply.lines) {
    const CommandLine split = split_command(line);
    if (split.verb != "JOINTS") continue;
    const std::vector<double> degrees = parse_numbers(split.rest);
    if (degrees.size() != 6) {
      throw RaplError("W2 reply has " + std::to_string(degrees.size()) + " joints: '" + line + "'");
    }
    JointArray radians;
    for (int i = 0; i < 6; ++i) radians[i] = from_degrees(degrees[i]);
    return radians;
  }
  throw RaplError("W2 reply without a JOINTS line" +
                  (reply.lines.empty() ? std::string() : ": '" + reply.lines.front() + "'"));
}

Location parse_location(const Reply& reply) {
  for (const std::string& line : reply.lines) {
    const CommandLine split = split_command(line);
    if (split.verb.empty() || split.verb.starts_with("***")) continue;
    std::vector<double> values;
    try {
      values = parse_numbers(split.rest);
    } catch (const RaplError&) {
      continue;  // not a location line
    }
    if (values.size() != 6) continue;
    Location location;
    // The name as sent (split.verb is upper-cased), after the separators split_command skips.
    const std::string_view named = std::string_view(line).substr(line.find_first_not_of(", \t"));
    location.name = std::string(named.substr(0, named.find_first_of(" \t")));  // as the verb ends
    for (int i = 0; i < 3; ++i) location.xyz[i] = from_inches(values[i]);
    for (int i = 0; i < 3; ++i) location.rpy[i] = from_degrees(values[3 + i]);
    return location;
  }
  throw RaplError("LLOC reply without a location line");
}

CommandLine split_command(std::string_view line) {
  while (!line.empty() && is_separator(line.front())) line.remove_prefix(1);
  const size_t space = line.find_first_of(" \t");
  CommandLine out;
  const std::string_view verb = line.substr(0, space);
  for (char c : verb) out.verb.push_back(static_cast<char>(std::toupper(static_cast<uint8_t>(c))));
  if (space != std::string_view::npos) out.rest = std::string(line.substr(space + 1));
  return out;
}

std::vector<double> parse_numbers(std::string_view text) {
  std::vector<double> values;
  size_t i = 0;
  while (i < text.size()) {
    if (is_separator(text[i])) {
      ++i;
      continue;
    }
    size_t end = i;
    while (end < text.size() && !is_separator(text[end])) ++end;
    const std::string_view field = text.substr(i, end - i);
    double value = 0;
    const auto [ptr, ec] = std::from_chars(field.data(), field.data() + field.size(), value);
    if (ec != std::errc() || ptr != field.data() + field.size() || !std::isfinite(value)) {
      throw RaplError("'" + std::string(field) + "' is not a number");
    }
    values.push_back(value);
    i = end;
  }
  return values;
}

std::string format_joints_reply(const JointArray& radians) {
  std::vector<double> degrees;
  for (double q : radians) degrees.push_back(to_degrees(q));
  return "JOINTS " + join(degrees, " ");
}

std::string format_location_reply(const Location& location) {
  std::vector<double> values;
  for (int i = 0; i < 3; ++i) values.push_back(to_inches(location.xyz[i]));
  for (int i = 0; i < 3; ++i) values.push_back(to_degrees(location.rpy[i]));
  return location.name + " " + join(values, " ");
}

}  // namespace sg::arm::rapl
