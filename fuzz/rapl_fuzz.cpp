// Drives the RAPL-II reply parser (arm_driver/rapl.hpp) with what the controller may send after
// a command's CR: every byte through rapl::ReplyReader (reset after each RaplError, as the link
// resynchronises), each complete reply through parse_joints (a W2 reply) and parse_location (an
// LLOC reply), and the whole input as a command line through split_command and parse_numbers
// (what the C550 emulator does with the host's lines).
// Asserts, beyond not crashing:
//  - only RaplError is thrown;
//  - a reply's lines are non-empty and hold no CR or LF; its error is its first `***` line;
//  - parsed joints and locations are finite, and printing them again is a fixed point: the
//    reply text format_joints_reply / format_location_reply writes parses back to values that
//    print the same (up to |value| < 1e9, where %.4f still resolves the degree/radian rounding),
//    and a location keeps its name;
//  - parse_numbers returns only finite numbers.

#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>

#include "arm_driver/rapl.hpp"
#include "fuzz/fuzz_support.hpp"

namespace rapl = sg::arm::rapl;

namespace {

bool moderate(double v) { return std::abs(v) < 1e9; }

rapl::Reply reply_of(const std::string& text) {
  return rapl::parse_reply_text(text);
}

void check_reply(const rapl::Reply& r) {
  bool error_seen = false;
  for (const std::string& line : r.lines) {
    SG_FUZZ_CHECK(!line.empty() && line.find_first_of("\r\n") == std::string::npos,
                  "reply line '%s'", line.c_str());
    if (!error_seen && line.starts_with("***")) {
      SG_FUZZ_CHECK(r.error && *r.error == line, "error is not the first *** line");
      error_seen = true;
    }
  }
  SG_FUZZ_CHECK(error_seen == r.error.has_value(), "error without a *** line");
}

void joints(const rapl::Reply& r) {
  rapl::JointArray q;
  try {
    q = rapl::parse_joints(r);
  } catch (const rapl::RaplError&) {
    return;
  }
  bool all_moderate = true;
  for (double v : q) {
    SG_FUZZ_CHECK(std::isfinite(v), "a joint is not finite");
    all_moderate = all_moderate && moderate(v);
  }
  if (!all_moderate) return;
  const std::string text = rapl::format_joints_reply(q);
  const rapl::JointArray again = rapl::parse_joints(reply_of(text));
  SG_FUZZ_CHECK(rapl::format_joints_reply(again) == text, "'%s' prints as '%s'", text.c_str(),
                rapl::format_joints_reply(again).c_str());
}

void location(const rapl::Reply& r) {
  rapl::Location l;
  try {
    l = rapl::parse_location(r);
  } catch (const rapl::RaplError&) {
    return;
  }
  for (int i = 0; i < 3; ++i) {
    SG_FUZZ_CHECK(std::isfinite(l.xyz[i]) && std::isfinite(l.rpy[i]), "not finite");
    if (!moderate(l.xyz[i]) || !moderate(l.rpy[i])) return;
  }
  const std::string text = rapl::format_location_reply(l);
  rapl::Location again;
  try {
    again = rapl::parse_location(reply_of(text));
  } catch (const rapl::RaplError& e) {
    SG_FUZZ_CHECK(false, "location '%s' (name '%s') does not parse back: %s", text.c_str(),
                  l.name.c_str(), e.what());
  }
  SG_FUZZ_CHECK(again.name == l.name, "name '%s' read back as '%s'", l.name.c_str(),
                again.name.c_str());
  SG_FUZZ_CHECK(rapl::format_location_reply(again) == text, "'%s' prints as '%s'", text.c_str(),
                rapl::format_location_reply(again).c_str());
}

void command_line(std::string_view line) {
  const rapl::CommandLine split = rapl::split_command(line);
  try {
    for (double v : rapl::parse_numbers(split.rest)) {
      SG_FUZZ_CHECK(std::isfinite(v), "parse_numbers returned a non-finite number");
    }
  } catch (const rapl::RaplError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  rapl::ReplyReader reader;
  for (size_t i = 0; i < size; ++i) {
    try {
      reader.feed(data[i]);
    } catch (const rapl::RaplError&) {
      reader.reset();
      continue;
    }
    if (!reader.complete()) continue;
    const rapl::Reply r = reader.reply();
    check_reply(r);
    joints(r);
    location(r);
    reader.reset();
  }
  command_line(std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}
