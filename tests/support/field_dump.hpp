#pragma once

#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>
#include <type_traits>
#include <vector>

#include "common/message_fields.hpp"
#include "common/message_types.hpp"

namespace sg::test {

/// Every field of a message as `path=value` lines in path order, in a form that a Java program
/// produces too (tests/lcmtypes/LcmDump.java): doubles by their bits (`d:7ff8000000000000`, so NaN
/// and -0.0 compare exactly), integers and booleans in decimal (booleans 0/1), strings and byte
/// arrays as hex (`s:...`, `x:...`; over 64 bytes as length and 64-bit FNV-1a hash,
/// `x:#921600:...`), array elements as `name[i]`.
class FieldDump {
 public:
  template <class T>
  void add(const std::string& name, const T& value) {
    if constexpr (std::is_same_v<T, double>) {
      uint64_t bits = 0;
      std::memcpy(&bits, &value, sizeof bits);
      char text[24];
      std::snprintf(text, sizeof text, "d:%016" PRIx64, bits);
      fields_[name] = text;
    } else if constexpr (std::is_integral_v<T>) {
      fields_[name] = std::to_string(static_cast<long long>(value));
    } else if constexpr (std::is_same_v<T, std::string>) {
      fields_[name] = "s:" + hex(value.data(), value.size());
    } else if constexpr (std::is_same_v<T, std::vector<uint8_t>>) {
      fields_[name] = "x:" + hex(value.data(), value.size());
    } else if constexpr (std::is_array_v<T> &&
                         std::is_same_v<std::remove_extent_t<T>, uint8_t>) {  // byte x[n], as Java
      fields_[name] = "x:" + hex(value, std::extent_v<T>);
    } else if constexpr (std::is_array_v<T>) {
      for (size_t i = 0; i < std::extent_v<T>; ++i)
        add(name + "[" + std::to_string(i) + "]", value[i]);
    } else {  // std::vector of anything else
      for (size_t i = 0; i < value.size(); ++i) add(name + "[" + std::to_string(i) + "]", value[i]);
    }
  }

  std::string text() const {
    std::string out;
    for (const auto& [path, value] : fields_) out += path + "=" + value + "\n";
    return out;
  }

 private:
  static std::string hex(const void* data, size_t size) {
    static const char* digits = "0123456789abcdef";
    std::string out;
    const auto* bytes = static_cast<const uint8_t*>(data);
    if (size > 64) {
      uint64_t hash = 0xcbf29ce484222325ULL;
      for (size_t i = 0; i < size; ++i) hash = (hash ^ bytes[i]) * 0x100000001b3ULL;
      char text[48];
      std::snprintf(text, sizeof text, "#%zu:%016" PRIx64, size, hash);
      return text;
    }
    for (size_t i = 0; i < size; ++i) {
      out += digits[bytes[i] >> 4];
      out += digits[bytes[i] & 15];
    }
    return out;
  }

  std::map<std::string, std::string> fields_;
};

/// The dump of one message, headed by its type name and fingerprint.
template <class Message>
std::string dump(Message message) {
  FieldDump d;
  visit_fields(message, d);
  char fingerprint[40];
  std::snprintf(fingerprint, sizeof fingerprint, "fingerprint=%016" PRIx64 "\n",
                static_cast<uint64_t>(Message::getHash()));
  return std::string("type=") + Message::getTypeName() + "\n" + fingerprint + d.text();
}

}  // namespace sg::test
