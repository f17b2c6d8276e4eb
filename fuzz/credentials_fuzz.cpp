// Drives the credentials file parser (auth/credentials_file.hpp, parse_credentials: what every
// program's --key reads when sg-lab made its credentials) with any text. Asserts, beyond never
// crashing and throwing nothing but LabKeyError: what parses writes back (format_credentials) to a
// text that parses to the same credentials; every name in it is a valid name, every channel a
// valid channel; at most 256 peers.

#include <string>

#include "auth/credentials_file.hpp"
#include "fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > sg::auth::kMaxCredentialsFile) return 0;  // the loader refuses larger files first
  const std::string text(reinterpret_cast<const char*>(data), size);
  sg::auth::Credentials c;
  try {
    c = sg::auth::parse_credentials(text, "fuzz.cred");
  } catch (const sg::auth::LabKeyError& e) {
    const std::string what = e.what();
    SG_FUZZ_CHECK(what.rfind("credentials fuzz.cred:", 0) == 0, "error '%s'", what.c_str());
    return 0;
  }
  SG_FUZZ_CHECK(sg::valid_vouch_name(c.identity), "identity '%s'", c.identity.c_str());
  SG_FUZZ_CHECK(c.send.size() + c.receive.size() <= 256, "%zu peers",
                c.send.size() + c.receive.size());
  for (const auto* peers : {&c.send, &c.receive})
    for (const sg::auth::Peer& p : *peers) {
      SG_FUZZ_CHECK(sg::valid_vouch_name(p.name), "peer '%s'", p.name.c_str());
      for (const std::string& ch : p.channels)
        SG_FUZZ_CHECK(sg::auth::valid_channel_name(ch), "channel '%s'", ch.c_str());
    }
  const std::string again = sg::auth::format_credentials(c, "fuzz");
  sg::auth::Credentials back;
  try {
    back = sg::auth::parse_credentials(again, "fuzz.cred");
  } catch (const sg::auth::LabKeyError& e) {
    SG_FUZZ_CHECK(false, "written credentials do not parse: %s", e.what());
  }
  SG_FUZZ_CHECK(sg::auth::same_credentials(c, back), "credentials do not round trip");
  return 0;
}
