#pragma once

/// Decoding that no message can crash or exhaust: the bytes are walked against the type's wire
/// layout, and every length they claim is checked against the bytes actually received and a
/// per-type bound, before LCM's generated decoder allocates anything.
///
///     stereograsp::trajectory_t t;
///     if (const sg::DecodeResult r = sg::safe_decode(data, size, t); !r) {
///       spdlog::warn("OBJECT_TRAJECTORY: {}", r.reason);   // "'position' claims 100000000 ..."
///       return;
///     }
///
/// Why: LCM 1.3.1's generated C++ decoders trust the lengths inside a message. A string length
/// of 0 makes `assign(p, -1)` throw std::length_error; an array length of -1 throws from
/// `resize`; a trajectory that claims 10^8 points in a 54-byte packet makes `resize` allocate
/// 10^8 vectors (2.4 GB) before the first point is found missing. An exception that leaves a
/// handler unwinds through LCM's C dispatch and aborts the process.
///
/// The wire layout (LCM's type specification): an 8-byte fingerprint, then the fields in .lcm
/// order, big-endian: int8_t/boolean/byte 1 byte, int16_t 2, int32_t/float 4, int64_t/double 8;
/// a fixed array is its elements one after another; a string is an int32 length L that counts a
/// terminating NUL, then L bytes (refused here when another NUL is inside); a variable array `x[n]`
/// is its elements, n being an earlier int32 field of the same message. The field order comes from
/// common/message_fields.hpp (the visitor reads a default-constructed message for the types only);
/// the variable arrays, their length fields and bounds from WireLimits below.

#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "common/message_fields.hpp"

namespace sg {

/// A variable-length array of a message: `name[length_field][inner]`.
struct VariableArray {
  const char* name;          ///< the array field
  const char* length_field;  ///< the int32 field before it that holds its length
  int64_t max_length;        ///< most entries accepted (the type's bound, well above any real use)
  int inner = 1;             ///< fixed elements per entry (3 for `position[num_points][3]`)
};

/// Per-type bounds of what a message may claim. Every string is at most kMaxString bytes; each
/// variable array is listed with its bound. **A new type with a variable array must list it
/// here**; safe_decode refuses a vector field it finds no entry for (tests/common/
/// safe_decode_test.cpp walks every type's encoded messages, so a missing entry fails there).
template <class M>
struct WireLimits {
  static constexpr int64_t kMaxString = 4096;
  static std::vector<VariableArray> arrays() { return {}; }
};
template <>
struct WireLimits<stereograsp::trajectory_t> {
  static constexpr int64_t kMaxString = 4096;
  /// The predictor forecasts 16 samples by default; other tools' paths may be longer.
  static std::vector<VariableArray> arrays() {
    return {{"position", "num_points", 65536, 3}, {"position_sigma", "num_points", 65536, 3}};
  }
};
template <>
struct WireLimits<stereograsp::process_status_t> {
  static constexpr int64_t kMaxString = 4096;
  /// The channels, peers and refusal rows a status lists are capped at 64 by sg::Bus.
  static std::vector<VariableArray> arrays() {
    return {{"channel", "num_channels", 64, 1},
            {"messages_in", "num_channels", 64, 1},
            {"messages_out", "num_channels", 64, 1},
            {"rate_in_hz", "num_channels", 64, 1},
            {"rate_out_hz", "num_channels", 64, 1},
            {"peer", "num_peers", 64, 1},
            {"peer_utime", "num_peers", 64, 1},
            {"peer_recv_utime", "num_peers", 64, 1},
            {"peer_offset_us", "num_peers", 64, 1},
            {"peer_offset_error_us", "num_peers", 64, 1},
            {"unvouched_channel", "num_unvouched", 64, 1},
            {"unvouched_sender", "num_unvouched", 64, 1},
            {"unvouched_verdict", "num_unvouched", 64, 1},
            {"unvouched_count", "num_unvouched", 64, 1}};
  }
};
template <>
struct WireLimits<stereograsp::image_t> {
  static constexpr int64_t kMaxString = 4096;
  /// 64 MiB: a 4096 x 4096 RGB frame is 48 MiB.
  static std::vector<VariableArray> arrays() { return {{"data", "size", int64_t{64} << 20, 1}}; }
};

/// What became of one decode: ok, or why not (one line: the field, the byte offset, the claim).
struct DecodeResult {
  bool ok = false;
  std::string reason;
  explicit operator bool() const { return ok; }
  static DecodeResult good() { return {true, {}}; }
  static DecodeResult refused(std::string why) { return {false, std::move(why)}; }
};

namespace wire {

/// The size on the wire of one scalar of C++ type T as lcm-gen declares it.
template <class T>
constexpr int scalar_size() {
  static_assert(std::is_arithmetic_v<T>, "not an LCM scalar");
  return static_cast<int>(sizeof(T));  // bool and int8_t/uint8_t are 1: LCM's boolean and byte
}

/// Big-endian int32 at p.
inline int64_t read_int32(const uint8_t* p) {
  const uint32_t v =
      (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | uint32_t{p[3]};
  return static_cast<int32_t>(v);
}

/// Walks one message's bytes field by field (a visitor for visit_fields).
template <class M>
class Walker {
 public:
  Walker(const uint8_t* data, int64_t size, int64_t pos) : data_(data), size_(size), pos_(pos) {}

  template <class T>
  void add(const char* name, const T&) {
    if (!error_.empty()) return;
    if constexpr (std::is_same_v<T, std::string>) {
      string_field(name);
    } else if constexpr (std::is_array_v<T>) {
      fixed_array<T>(name);
    } else if constexpr (std::is_arithmetic_v<T>) {
      scalar<T>(name);
    } else {
      variable_array<T>(name);
    }
  }

  int64_t position() const { return pos_; }
  const std::string& error() const { return error_; }

 private:
  bool take(const char* name, int64_t bytes, const char* what) {
    if (bytes <= size_ - pos_) {
      pos_ += bytes;
      return true;
    }
    fail(name, what + std::string(" needs ") + std::to_string(bytes) + " bytes, " +
                   std::to_string(size_ - pos_) + " left");
    return false;
  }

  void fail(const char* name, const std::string& why) {
    error_ = std::string("field '") + name + "' at byte " + std::to_string(pos_) + ": " + why;
  }

  template <class T>
  void scalar(const char* name) {
    const int64_t at = pos_;
    if (!take(name, scalar_size<T>(), "the value")) return;
    if constexpr (std::is_same_v<T, int32_t>) {
      lengths_.push_back({name, read_int32(data_ + at)});
    }
  }

  template <class T>
  void fixed_array(const char* name) {
    using Element = std::remove_all_extents_t<T>;
    static_assert(std::is_arithmetic_v<Element>, "fixed arrays of strings are not supported");
    take(name, static_cast<int64_t>(sizeof(T) / sizeof(Element)) * scalar_size<Element>(),
         "the array");
  }

  void string_field(const char* name) {
    if (!take(name, 4, "the length")) return;
    const int64_t length = read_int32(data_ + pos_ - 4);  // counts the terminating NUL
    if (length < 1 || length > WireLimits<M>::kMaxString + 1) {
      pos_ -= 4;
      fail(name, "string length " + std::to_string(length) + " outside 1.." +
                     std::to_string(WireLimits<M>::kMaxString + 1));
      return;
    }
    const int64_t start = pos_;
    if (!take(name, length, "the string")) return;
    if (data_[start + length - 1] != 0) return fail(name, "string not terminated by NUL");
    // An inner NUL would decode, but re-encode shorter than its size (LCM encodes with strlen):
    // a process echoing it (a sender name in a status) could then not publish.
    if (std::memchr(data_ + start, 0, static_cast<size_t>(length - 1)) != nullptr) {
      fail(name, "string holds a NUL before its end");
    }
  }

  template <class T>
  void variable_array(const char* name) {
    using Element = typename T::value_type;
    const VariableArray* spec = find_spec(name);
    if (spec == nullptr) return fail(name, "no bound declared for this array (WireLimits)");
    const int64_t* count = find_length(spec->length_field);
    if (count == nullptr) return fail(name, "its length field is not before it");
    if (*count < 0 || *count > spec->max_length) {
      return fail(name, "claims " + std::to_string(*count) + " entries (" + spec->length_field +
                            "), must be 0.." + std::to_string(spec->max_length));
    }
    if constexpr (std::is_same_v<Element, std::string>) {  // each string checked as a field
      for (int64_t i = 0; i < *count && error_.empty(); ++i) string_field(name);
    } else {
      int element_size = 0;
      if constexpr (std::is_arithmetic_v<Element>) {
        element_size = scalar_size<Element>();
      } else {
        static_assert(std::is_arithmetic_v<typename Element::value_type>, "nested too deep");
        element_size = scalar_size<typename Element::value_type>();
      }
      take(name, *count * spec->inner * element_size, "the array");
    }
  }

  const VariableArray* find_spec(const char* name) {
    if (specs_.empty()) specs_ = WireLimits<M>::arrays();
    for (const auto& s : specs_)
      if (std::strcmp(s.name, name) == 0) return &s;
    return nullptr;
  }

  const int64_t* find_length(const char* field) const {
    for (const auto& [n, v] : lengths_)
      if (std::strcmp(n, field) == 0) return &v;
    return nullptr;
  }

  const uint8_t* data_;
  int64_t size_;
  int64_t pos_;
  std::string error_;
  std::vector<std::pair<const char*, int64_t>> lengths_;  // int32 fields seen, by name
  std::vector<VariableArray> specs_;
};

}  // namespace wire

/// Checks that `data[0, size)` is exactly one well-formed M: its fingerprint, every field within
/// the bytes, every claimed length within WireLimits<M>, nothing after the end. Allocates
/// nothing that depends on the message.
template <class M>
DecodeResult check_wire(const uint8_t* data, int64_t size) {
  const char* type = M::getTypeName();
  if (data == nullptr || size < 8) {
    return DecodeResult::refused(std::to_string(size) + " bytes: too short for a " + type);
  }
  uint64_t hash = 0;
  for (int i = 0; i < 8; ++i) hash = (hash << 8) | data[i];
  if (hash != static_cast<uint64_t>(M::getHash())) {
    return DecodeResult::refused("not a " + std::string(type) + " (another fingerprint)");
  }
  static const M prototype{};
  wire::Walker<M> walker(data, size, 8);
  visit_fields(prototype, walker);
  if (!walker.error().empty())
    return DecodeResult::refused(std::string(type) + " " + walker.error());
  if (walker.position() != size) {
    return DecodeResult::refused(std::to_string(size - walker.position()) +
                                 " bytes after the end of a " + type);
  }
  return DecodeResult::good();
}

/// check_wire, then LCM's own decoder (which can then neither throw nor over-allocate; should it
/// throw all the same, the exception is caught and reported as a refusal).
template <class M>
DecodeResult safe_decode(const uint8_t* data, int64_t size, M& out) {
  if (DecodeResult checked = check_wire<M>(data, size); !checked) return checked;
  try {
    if (out.decode(data, 0, static_cast<int>(size)) != size) {
      return DecodeResult::refused(std::string("LCM's decoder refused a ") + M::getTypeName());
    }
  } catch (const std::exception& e) {
    return DecodeResult::refused(std::string("LCM's decoder threw: ") + e.what());
  }
  return DecodeResult::good();
}

}  // namespace sg
