#include "auth/credentials_file.hpp"

#include <sodium.h>

#include <algorithm>
#include <sstream>

namespace sg::auth {
namespace {

constexpr char kHeader[] = "stereograsp-credentials 1";
constexpr std::size_t kMaxPeers = 256;

std::string hex(const uint8_t* bytes, std::size_t n) {
  std::string out(2 * n + 1, '\0');
  sodium_bin2hex(out.data(), out.size(), bytes, n);
  out.pop_back();
  return out;
}

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& i : items) out += (out.empty() ? "" : ",") + i;
  return out;
}

/// Reads one line's words, failing with the file and line.
class LineReader {
 public:
  LineReader(const std::string& path, int line, const std::string& text)
      : path_(path), line_(line), in_(text) {}
  [[noreturn]] void fail(const std::string& why) const {
    throw LabKeyError("credentials " + path_ + ":" + std::to_string(line_) + ": " + why);
  }
  std::string word(const char* what) {
    std::string w;
    if (!(in_ >> w)) fail(std::string("expected ") + what);
    return w;
  }
  std::string name(const char* what) {
    std::string n = word(what);
    if (!valid_vouch_name(n)) fail(std::string("not a ") + what + ": '" + n.substr(0, 40) + "'");
    return n;
  }
  std::array<uint8_t, 32> key() {
    const std::string h = word("a key of 64 hex characters");
    std::array<uint8_t, 32> bytes{};
    std::size_t decoded = 0;
    if (h.size() != 64 ||
        sodium_hex2bin(bytes.data(), bytes.size(), h.data(), h.size(), nullptr, &decoded,
                       nullptr) != 0 ||
        decoded != bytes.size())
      fail("a key is 64 hex characters");
    return bytes;
  }
  std::vector<std::string> channels() {
    std::vector<std::string> out;
    std::stringstream list(word("a comma-separated list of channels"));
    for (std::string c; std::getline(list, c, ',');) {
      if (!valid_channel_name(c)) fail("not a channel: '" + c.substr(0, 64) + "'");
      out.push_back(c);
    }
    if (out.empty()) fail("no channels");
    return out;
  }
  void end() {
    std::string extra;
    if (in_ >> extra) fail("unexpected '" + extra.substr(0, 40) + "' at the end of the line");
  }

 private:
  const std::string& path_;
  int line_;
  std::istringstream in_;
};

/// Adds a send or receive peer from `r`, refusing a peer named twice.
void add_peer(LineReader& r, std::vector<Peer>& peers, const char* kind) {
  Peer p;
  p.name = r.name("peer name");
  p.key = PairKey(r.key());
  p.channels = r.channels();
  r.end();
  for (const Peer& q : peers)
    if (q.name == p.name) r.fail(std::string(kind) + " " + p.name + " named twice");
  peers.push_back(std::move(p));
}

}  // namespace

bool same_credentials(const Credentials& a, const Credentials& b) {
  const auto same_peers = [](const std::vector<Peer>& x, const std::vector<Peer>& y) {
    return std::equal(x.begin(), x.end(), y.begin(), y.end(), [](const Peer& p, const Peer& q) {
      return p.name == q.name && p.key.bytes() == q.key.bytes() && p.channels == q.channels;
    });
  };
  const bool keys = a.command_key.has_value() == b.command_key.has_value() &&
                    (!a.command_key || a.command_key->bytes() == b.command_key->bytes());
  return a.identity == b.identity && keys && same_peers(a.send, b.send) &&
         same_peers(a.receive, b.receive);
}

bool valid_channel_name(const std::string& name) {
  if (name.empty() || name.size() > 63) return false;
  return std::all_of(name.begin(), name.end(),
                     [](char c) { return c > ' ' && c < 127 && c != ','; });
}

std::string format_credentials(const Credentials& c, const std::string& comment) {
  std::string out = "# " + comment + "\n# made by sg-lab from the lab key; keep it mode 0600\n";
  out += std::string(kHeader) + "\nidentity " + c.identity + "\n";
  if (c.command_key) out += "command-key " + hex(c.command_key->bytes().data(), 32) + "\n";
  for (const Peer& p : c.send)
    out += "send " + p.name + " " + hex(p.key.bytes().data(), 32) + " " + join(p.channels) + "\n";
  for (const Peer& p : c.receive)
    out +=
        "receive " + p.name + " " + hex(p.key.bytes().data(), 32) + " " + join(p.channels) + "\n";
  return out;
}

Credentials parse_credentials(const std::string& text, const std::string& path) {
  Credentials c;
  std::istringstream in(text);
  int line_no = 0;
  bool header = false;
  for (std::string line; std::getline(in, line);) {
    LineReader r(path, ++line_no, line);
    if (line.empty() || line[0] == '#') continue;
    if (!header) {
      if (line != kHeader) r.fail(std::string("expected '") + kHeader + "' first");
      header = true;
      continue;
    }
    const std::string word = r.word("a word");
    if (word == "identity") {
      if (!c.identity.empty()) r.fail("a second identity");
      c.identity = r.name("identity");
      r.end();
    } else if (word == "command-key") {
      if (c.command_key) r.fail("a second command-key");
      c.command_key = LabKey(r.key());
      r.end();
    } else if (word == "send" || word == "receive") {
      add_peer(r, word == "send" ? c.send : c.receive, word.c_str());
      if (c.send.size() + c.receive.size() > kMaxPeers) r.fail("more than 256 peers");
    } else {
      r.fail("unknown word '" + word.substr(0, 40) + "' (identity, command-key, send, receive)");
    }
  }
  if (!header) LineReader(path, line_no, "").fail(std::string("no '") + kHeader + "' line");
  if (c.identity.empty()) LineReader(path, line_no, "").fail("no identity");
  return c;
}

void write_credentials_file(const std::string& path, const Credentials& credentials,
                            const std::string& comment) {
  std::string text = format_credentials(credentials, comment);
  write_secret_file(path, text);
  sodium_memzero(text.data(), text.size());
}

Credentials load_key_file(const std::string& path, const std::string& identity) {
  std::string text = read_secret_file(path, kMaxCredentialsFile);
  if (text.find(kHeader) == std::string::npos) {  // the lab key itself
    sodium_memzero(text.data(), text.size());
    return credentials_from_lab_key(LabKey::load(path), identity);
  }
  Credentials c;
  try {
    c = parse_credentials(text, path);
  } catch (...) {
    sodium_memzero(text.data(), text.size());
    throw;
  }
  sodium_memzero(text.data(), text.size());
  if (c.identity != identity)
    throw LabKeyError("credentials " + path + ": these are " + c.identity + "'s, not " + identity +
                      "'s");
  return c;
}

}  // namespace sg::auth
