// Drives the host side of the serial line, arm_driver's C550Link (the code that parses every
// byte the controller sends), against a controller that answers with the fuzz input: byte 0
// picks one operation (open_session, enquire, read_joints, a motion command, read_location,
// read_memory, write_memory, close_session, resynchronise); the rest is what the line delivers,
// one byte every 0.26 ms (38,400 baud), then silence. Time is simulated, so time-outs cost
// nothing.
// Asserts, beyond not crashing or hanging:
//  - the link throws only what ArmDriver catches and handles: LinkError (a protocol fault),
//    ControllerError (a `***` reply to a command) — anything else (RaplError, AciError,
//    std::length_error, ...) would end the driver's worker thread;
//  - a read_memory that returns gives exactly the bytes asked for;
//  - a read_joints that returns gives finite angles;
//  - the link never reads more bytes than the line delivered (stats().bytes_read).

#include <cmath>
#include <cstdint>
#include <mutex>
#include <optional>
#include <span>
#include <vector>

#include "arm_driver/c550_link.hpp"
#include "common/clock.hpp"
#include "fuzz/fuzz_support.hpp"

namespace arm = sg::arm;

namespace {

/// Simulated time: waiting moves it on at once.
class InstantClock final : public sg::Clock {
 public:
  double now() override { return t_; }
  int64_t utime() override { return static_cast<int64_t>(t_ * 1e6); }
  bool wait_until(std::unique_lock<std::mutex>&, double deadline,
                  const std::function<bool()>& ready, std::stop_token) override {
    if (ready()) return true;
    advance_to(deadline);
    return ready();
  }
  void notify() override {}
  void sleep_until(double deadline) override { advance_to(deadline); }
  void advance(double seconds) { t_ += seconds; }

 private:
  void advance_to(double deadline) { t_ = std::max(t_, deadline); }
  double t_ = 0;
};

/// The controller's side: the fuzz bytes, then silence. What the host writes is dropped.
class ScriptedLine final : public arm::ByteStream {
 public:
  ScriptedLine(std::span<const uint8_t> bytes, InstantClock& clock)
      : bytes_(bytes), clock_(clock) {}
  void write(std::span<const uint8_t>) override {}
  std::optional<uint8_t> read_byte(std::chrono::microseconds timeout) override {
    if (next_ == bytes_.size()) {
      clock_.advance(std::chrono::duration<double>(timeout).count());
      return std::nullopt;
    }
    clock_.advance(10.0 / 38400);
    return bytes_[next_++];
  }
  void discard_input() override {}  // nothing has "arrived" ahead of the reads
  size_t delivered() const { return next_; }

 private:
  std::span<const uint8_t> bytes_;
  InstantClock& clock_;
  size_t next_ = 0;
};

void operate(arm::C550Link& link, uint8_t op, std::span<const uint8_t> rest) {
  switch (op % 9) {
    case 0: link.open_session(); break;
    case 1: link.enquire(); break;
    case 2: {
      const arm::rapl::JointArray q = link.read_joints();
      for (double v : q) SG_FUZZ_CHECK(std::isfinite(v), "read_joints gave a non-finite angle");
      break;
    }
    case 3: link.command(arm::rapl::move_joints({0.1, -0.2, 0.3, 0, 0.5, 0}), {}); break;
    case 4: (void)link.read_location("P1"); break;
    case 5: {
      const int length = rest.empty() ? 1 : 1 + rest[0] * 129;  // 1..32896: past the limit too
      std::vector<uint8_t> got;
      try {
        got = link.read_memory(arm::aci::kMemPointerList, 0, 0, length);
      } catch (const arm::aci::AciError&) {
        if (length <= arm::aci::kMaxTransfer) throw;  // refusing an oversized request is right
        return;
      }
      SG_FUZZ_CHECK(got.size() == static_cast<size_t>(length), "read %zu of %d bytes",
                    got.size(), length);
      break;
    }
    case 6: link.write_memory(arm::aci::kMemSegment, 0, 0x100, std::vector<uint8_t>(300, 0x5A)); break;
    case 7: link.close_session(); break;
    default: link.resynchronise(); break;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  InstantClock clock;
  ScriptedLine line(std::span(data + 1, size - 1), clock);
  arm::C550Link link(line, 1, arm::LinkTiming{}, clock);
  try {
    operate(link, data[0], std::span(data + 1, size - 1));
  } catch (const arm::LinkError&) {
  } catch (const arm::ControllerError&) {
  }
  SG_FUZZ_CHECK(link.stats().bytes_read <= static_cast<int64_t>(line.delivered()),
                "read %lld bytes, the line delivered %zu",
                static_cast<long long>(link.stats().bytes_read), line.delivered());
  return 0;
}
