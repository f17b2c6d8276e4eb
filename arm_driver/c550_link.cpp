#include "arm_driver/c550_link.hpp"

#include <spdlog/spdlog.h>


namespace sg::arm {

using namespace aci;

namespace {
double seconds(milliseconds ms) { return std::chrono::duration<double>(ms).count(); }
}  // namespace

C550Link::C550Link(ByteStream& line, int slave, LinkTiming timing, Clock& clock)
    : line_(line), slave_(slave), timing_(timing), clock_(clock) {
  slave_byte(slave);  // validates 1..127
}

void C550Link::send(std::span<const uint8_t> bytes) {
  line_.write(bytes);
  stats_.bytes_written += static_cast<int64_t>(bytes.size());
}

uint8_t C550Link::expect_raw(const char* what, milliseconds timeout) {
  const auto byte = line_.read_byte(timeout);
  if (!byte) {
    throw LinkError(std::string("no ") + what + " within " + std::to_string(timeout.count()) +
                    " ms");
  }
  ++stats_.bytes_read;
  return *byte;
}

uint8_t C550Link::expect_text(const char* what, milliseconds timeout) {
  for (;;) {
    const uint8_t byte = expect_raw(what, timeout);
    if (byte != rapl::XON && byte != rapl::XOFF) return byte;
  }
}

std::vector<uint8_t> C550Link::read_exact(size_t n, const char* what) {
  std::vector<uint8_t> bytes;
  bytes.reserve(n);
  while (bytes.size() < n) bytes.push_back(expect_raw(what, timing_.byte_timeout));
  return bytes;
}

void C550Link::enquire() {
  const auto enquiry = encode_enquiry(slave_);
  const auto answer = encode_enquiry_reply(slave_);
  for (int attempt = 0; attempt < timing_.enquiry_tries; ++attempt) {
    if (attempt) ++stats_.retries;
    line_.discard_input();
    send(enquiry);
    try {
      if (read_exact(3, "enquiry answer") == std::vector<uint8_t>(answer.begin(), answer.end())) {
        return;
      }
    } catch (const LinkError&) {
      // no answer this time: ask again
    }
  }
  throw LinkError("the controller (slave " + std::to_string(slave_) + ") did not answer " +
                  std::to_string(timing_.enquiry_tries) + " enquiries");
}

void C550Link::send_header(const AciHeader& header) {
  const auto bytes = encode_header(header);
  for (int attempt = 0; attempt < timing_.retries; ++attempt) {
    if (attempt) ++stats_.retries;
    send(bytes);
    try {
      const uint8_t answer = expect_raw("answer to the ACI header", timing_.byte_timeout);
      if (answer == ACK) return;
    } catch (const LinkError&) {
      // time-out: send again
    }
  }
  throw LinkError("the controller refused the ACI header " + std::to_string(timing_.retries) +
                  " times");
}

void C550Link::send_blocks(const std::vector<uint8_t>& data) {
  const auto frames = encode_blocks(data);
  for (size_t i = 0; i < frames.size(); ++i) {
    bool acknowledged = false;
    for (int attempt = 0; attempt < timing_.retries && !acknowledged; ++attempt) {
      if (attempt) ++stats_.retries;
      send(frames[i]);
      try {
        acknowledged = expect_raw("answer to an ACI block", timing_.byte_timeout) == ACK;
      } catch (const LinkError&) {
      }
    }
    if (!acknowledged) {
      throw LinkError("ACI block " + std::to_string(i + 1) + " of " +
                      std::to_string(frames.size()) + " not acknowledged after " +
                      std::to_string(timing_.retries) + " tries");
    }
  }
  const uint8_t eot = EOT;
  send({&eot, 1});
}

std::vector<uint8_t> C550Link::receive_blocks(int length) {
  const BlockLayout layout = block_layout(length);
  std::vector<uint8_t> data;
  for (int i = 0; i < layout.total_blocks(); ++i) {
    const int size = i == layout.full_blocks ? layout.last_size : kBlockSize;
    bool received = false;
    std::string last_error;
    for (int attempt = 0; attempt < timing_.retries && !received; ++attempt) {
      if (attempt) ++stats_.retries;
      try {
        while (expect_raw("ACI block", timing_.byte_timeout) != STX) {
        }
        std::vector<uint8_t> frame{STX};
        const auto rest = read_exact(static_cast<size_t>(size) + 2, "ACI block byte");
        frame.insert(frame.end(), rest.begin(), rest.end());
        const Block block = decode_block(frame);
        if (block.last != (i == layout.full_blocks)) throw AciError("block ends early or late");
        data.insert(data.end(), block.data.begin(), block.data.end());
        received = true;
      } catch (const std::exception& e) {  // AciError or LinkError (time-out)
        last_error = e.what();
        line_.discard_input();
      }
      const uint8_t answer = received ? ACK : NAK;
      send({&answer, 1});
    }
    if (!received) {
      throw LinkError("ACI block " + std::to_string(i + 1) + " unreadable after " +
                      std::to_string(timing_.retries) + " tries: " + last_error);
    }
  }
  if (expect_raw("EOT ending the ACI read", timing_.byte_timeout) != EOT) {
    throw LinkError("the ACI read did not end with EOT");
  }
  const uint8_t eot = EOT;
  send({&eot, 1});
  return data;
}

std::vector<uint8_t> C550Link::read_memory(uint8_t memtype, uint16_t segment, uint16_t offset,
                                           int length) {
  const AciHeader header{slave_, false, memtype, offset, segment, length};
  encode_header(header);  // refuses a length with no encoding before anything is sent
  enquire();
  send_header(header);
  return receive_blocks(length);
}

void C550Link::write_memory(uint8_t memtype, uint16_t segment, uint16_t offset,
                            const std::vector<uint8_t>& data) {
  const AciHeader header{slave_, true, memtype, offset, segment, static_cast<int>(data.size())};
  encode_header(header);
  enquire();
  send_header(header);
  send_blocks(data);
}

void C550Link::leave_command_mode() {
  const uint8_t interrupt = rapl::CTRL_C;
  send({&interrupt, 1});
  clock_.sleep_for(seconds(timing_.session_settle));
  const std::string help = "HELP\r";
  send({reinterpret_cast<const uint8_t*>(help.data()), help.size()});
  drain(2.0);
  const uint8_t leave[] = {rapl::CTRL_Z, rapl::CTRL_Z};
  send(leave);
  clock_.sleep_for(seconds(timing_.session_settle));
  line_.discard_input();
}

void C550Link::drain(double at_most) {
  const double give_up = clock_.now() + at_most;
  while (clock_.now() < give_up && line_.read_byte(timing_.byte_timeout)) {
    ++stats_.bytes_read;
  }
}

void C550Link::open_session() {
  leave_command_mode();
  read_memory(kMemSession, 0, 0, 1);
  clock_.sleep_for(seconds(timing_.session_settle));
  const uint8_t interrupt = rapl::CTRL_C;
  send({&interrupt, 1});
  clock_.sleep_for(seconds(timing_.session_settle));
  line_.discard_input();
  command("NOH", timing_.reply_timeout);
}

void C550Link::close_session() {
  command("HELP", timing_.reply_timeout);
  const uint8_t bytes[] = {rapl::CTRL_Z, rapl::CTRL_Z};
  send(bytes);
}

void C550Link::echo_line(const std::string& text) {
  for (const char c : text) {
    const auto byte = static_cast<uint8_t>(c);
    send({&byte, 1});
    uint8_t echo = 0;
    try {
      echo = expect_text("echo", timing_.byte_timeout);
    } catch (const LinkError& e) {
      resynchronise();
      throw LinkError("'" + text + "': " + e.what() + " of " + byte_name(byte));
    }
    if (echo != byte) {
      resynchronise();
      throw LinkError("'" + text + "': echo of " + byte_name(byte) + " came back as " +
                      byte_name(echo) + "; line cancelled");
    }
  }
}

rapl::Reply C550Link::command(const std::string& text, milliseconds reply_timeout) {
  delivered_ = false;
  if (text.empty() || text.size() > rapl::kMaxLine) {
    throw LinkError("command of " + std::to_string(text.size()) + " characters (1.." +
                    std::to_string(rapl::kMaxLine) + ")");
  }
  echo_line(text);
  const uint8_t cr = rapl::CR;
  send({&cr, 1});
  delivered_ = true;
  rapl::ReplyReader reader;
  try {
    while (!reader.complete()) {
      reader.feed(expect_text(reader.acknowledged() ? "reply byte" : "ACK",
                              reader.acknowledged() ? timing_.byte_timeout : reply_timeout));
    }
  } catch (const std::exception& e) {  // LinkError (time-out) or RaplError (garbled)
    resynchronise();
    throw LinkError("reply to '" + text + "': " + e.what());
  }
  rapl::Reply reply = reader.reply();
  spdlog::debug("C550: '{}' -> {}", text,
                reply.error ? *reply.error
                            : (reply.lines.empty() ? std::string("ACK") : reply.lines.front()));
  if (reply.error) throw ControllerError("'" + text + "': " + *reply.error);
  return reply;
}

rapl::JointArray C550Link::read_joints() {
  const rapl::Reply reply = command("W2", timing_.reply_timeout);
  try {
    return rapl::parse_joints(reply);
  } catch (const rapl::RaplError& e) {
    throw LinkError(e.what());
  }
}

rapl::Location C550Link::read_location(const std::string& name) {
  const rapl::Reply reply = command(rapl::lloc(name), timing_.reply_timeout);
  try {
    return rapl::parse_location(reply);
  } catch (const rapl::RaplError& e) {
    throw LinkError(e.what());
  }
}

void C550Link::resynchronise() {
  ++stats_.resyncs;
  const uint8_t interrupt = rapl::CTRL_C;
  send({&interrupt, 1});
  std::string tail;
  const double give_up = clock_.now() + 2.0;
  while (clock_.now() < give_up) {
    const auto byte = line_.read_byte(timing_.byte_timeout);
    if (!byte) return;  // quiet: whatever was in flight has ended
    tail.push_back(static_cast<char>(*byte));
    if (tail.ends_with(rapl::kPrompt)) {
      // drain a second prompt (one for the cancelled command, one for ^C) if it follows at once
      tail.clear();
    }
  }
}

}  // namespace sg::arm
