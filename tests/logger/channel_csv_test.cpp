// ChannelCsv and CsvWriter (logger/channel_csv.hpp): exact CSV text for known messages,
// refusal of bytes that are not exactly a stereograsp type, quoting, NaN, and every field of
// every type read back from the text unchanged.

#include "logger/channel_csv.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "common/message_types.hpp"
#include "tests/support/sample_messages.hpp"
#include "tests/support/subprocess.hpp"

namespace sg::logger {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A new temporary directory, removed with its contents at the end of the test.
struct TempDir {
  TempDir() : path(test::make_temp_dir()) {}
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
  std::string path;
};

// RFC 4180 parsing: rows of cells, quotes removed and doubled quotes undone.
std::vector<std::vector<std::string>> parse_csv(const std::string& text) {
  std::vector<std::vector<std::string>> rows(1);
  std::string cell;
  bool quoted = false, in_quotes = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_quotes) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
        cell += '"';
        ++i;
      } else if (c == '"') {
        in_quotes = false;
      } else {
        cell += c;
      }
    } else if (c == '"') {
      in_quotes = quoted = true;
    } else if (c == ',' || c == '\n') {
      rows.back().push_back(cell);
      cell.clear();
      quoted = false;
      if (c == '\n') rows.emplace_back();
    } else {
      cell += c;
    }
  }
  if (!cell.empty() || quoted) rows.back().push_back(cell);
  if (rows.back().empty()) rows.pop_back();
  return rows;
}

template <class T>
std::vector<uint8_t> bytes_of(const T& message) {
  return encode_message(message);
}

stereograsp::point3_t sample_point() {
  stereograsp::point3_t p{};
  p.utime = 1700000000000001;
  p.visible = 1;
  p.position[0] = 0.5;
  p.position[1] = -0.25;
  p.position[2] = 0.1;
  p.position_sigma[0] = p.position_sigma[1] = p.position_sigma[2] = kNaN;
  p.reprojection_error = 0.75;
  p.seen_by = 3;
  p.flags = 4;
  return p;
}

// A point3_t gives exactly the expected header and row; NaN is "nan", 0.1 has 17 digits.
TEST(CsvWriter, Point3ExactText) {
  CsvWriter writer;
  EXPECT_EQ(writer.type_name(), "");
  std::ostringstream out;
  const std::vector<uint8_t> bytes = bytes_of(sample_point());
  ASSERT_TRUE(writer.write(out, 1700000000000100, bytes.data(), static_cast<int>(bytes.size())));
  EXPECT_EQ(out.str(),
            "recv_utime,utime,visible,position_0,position_1,position_2,position_sigma_0,"
            "position_sigma_1,position_sigma_2,reprojection_error,seen_by,flags\n"
            "1700000000000100,1700000000000001,1,0.5,-0.25,0.10000000000000001,nan,nan,nan,0.75,"
            "3,4\n");
  EXPECT_EQ(writer.type_name(), "point3_t");
  EXPECT_EQ(writer.rows(), 1);
  EXPECT_EQ(writer.columns().size(), 12u);
}

// Several channels and types: one file per channel, each with exactly the expected text.
TEST(ChannelCsv, SeveralTypesExactFiles) {
  const TempDir temp;
  const std::string dir = temp.path + "/csv";
  {
    ChannelCsv csv(dir);
    stereograsp::grasp_command_t command{};
    command.utime = 5;
    command.sequence = 7;
    command.command = stereograsp::grasp_command_t::COMMAND_GRASP;
    command.standoff = 0.125;
    command.sender = "op, \"bob\"";
    std::vector<uint8_t> bytes = bytes_of(command);
    EXPECT_TRUE(csv.add("GRASP_COMMAND", 100, bytes.data(), static_cast<int>(bytes.size())));

    stereograsp::trajectory_t trajectory{};
    trajectory.utime = 10;
    trajectory.source_utime = 9;
    trajectory.start_utime = 11;
    trajectory.period_us = 250000;
    trajectory.num_points = 2;
    trajectory.position = {{1, 2, 3}, {4.5, -5, 6}};
    trajectory.position_sigma = {{0.5, 0.25, 0.125}, {1, 2, 4}};
    trajectory.status = stereograsp::trajectory_t::STATUS_TRACKING;
    trajectory.model = stereograsp::trajectory_t::MODEL_BURG;
    trajectory.model_order = 8;
    bytes = bytes_of(trajectory);
    EXPECT_TRUE(csv.add("OBJECT_TRAJECTORY", 101, bytes.data(), static_cast<int>(bytes.size())));

    stereograsp::image_t image{};
    image.utime = 20;
    image.camera = stereograsp::image_t::RIGHT;
    image.frame_number = 3;
    image.width = 2;
    image.height = 1;
    image.row_stride = 2;
    image.pixel_format = stereograsp::image_t::FORMAT_GRAY8;
    image.data = {7, 9};
    image.size = 2;
    bytes = bytes_of(image);
    EXPECT_TRUE(csv.add("CAMERA_RIGHT", 102, bytes.data(), static_cast<int>(bytes.size())));

    command.sequence = 8;
    command.sender = "";
    bytes = bytes_of(command);
    EXPECT_TRUE(csv.add("GRASP_COMMAND", 103, bytes.data(), static_cast<int>(bytes.size())));

    EXPECT_EQ(csv.files(),
              (std::vector<std::string>{dir + "/GRASP_COMMAND.csv", dir + "/OBJECT_TRAJECTORY.csv",
                                        dir + "/CAMERA_RIGHT.csv"}));
    csv.flush();
    // Written as they come: the rows are on disk after flush(), before destruction.
    EXPECT_EQ(test::count_lines(test::read_text(dir + "/GRASP_COMMAND.csv")), 3);
  }
  // auth_counter and the 32 bytes of auth_tag (unsigned: zero) follow the sender.
  std::string auth_names = ",auth_counter", auth_zeros = ",0";
  for (int i = 0; i < 32; ++i) auth_names += ",auth_tag_" + std::to_string(i), auth_zeros += ",0";
  EXPECT_EQ(test::read_text(dir + "/GRASP_COMMAND.csv"),
            "recv_utime,utime,sequence,command,standoff,sender" + auth_names + "\n" +
                "100,5,7,2,0.125,\"op, \"\"bob\"\"\"" + auth_zeros + "\n" + "103,5,8,2,0.125,\"\"" +
                auth_zeros + "\n");
  EXPECT_EQ(test::read_text(dir + "/OBJECT_TRAJECTORY.csv"),
            "recv_utime,utime,source_utime,start_utime,period_us,num_points,position_0_0,"
            "position_0_1,position_0_2,position_1_0,position_1_1,position_1_2,position_sigma_0_0,"
            "position_sigma_0_1,position_sigma_0_2,position_sigma_1_0,position_sigma_1_1,"
            "position_sigma_1_2,occluded_samples,status,model,model_order\n"
            "101,10,9,11,250000,2,1,2,3,4.5,-5,6,0.5,0.25,0.125,1,2,4,0,1,1,8\n");
  EXPECT_EQ(test::read_text(dir + "/CAMERA_RIGHT.csv"),
            "recv_utime,utime,camera,frame_number,width,height,row_stride,pixel_format,size\n"
            "102,20,1,3,2,1,2,1,2\n");
  // The quoted string reads back with its comma and quotes.
  const auto rows = parse_csv(test::read_text(dir + "/GRASP_COMMAND.csv"));
  ASSERT_EQ(rows.size(), 3u);
  ASSERT_EQ(rows[1].size(), 6u + 33u);
  EXPECT_EQ(rows[1][5], "op, \"bob\"");
}

// Bytes that do not decode exactly as a (the channel's) stereograsp type are refused, unwritten.
TEST(ChannelCsv, RefusesUndecodableBytes) {
  const TempDir temp;
  ChannelCsv csv(temp.path);
  std::vector<uint8_t> good = bytes_of(sample_point());
  const int size = static_cast<int>(good.size());
  EXPECT_EQ(ChannelCsv::type_name(good.data(), size), "point3_t");

  std::vector<uint8_t> longer = good;
  longer.push_back(0);
  std::vector<uint8_t> unknown = good;
  unknown[0] ^= 0xff;
  const std::vector<uint8_t> tiny = {1, 2, 3};
  EXPECT_FALSE(csv.add("NEVER", 1, good.data(), size - 1));
  EXPECT_FALSE(csv.add("NEVER", 2, longer.data(), size + 1));
  EXPECT_FALSE(csv.add("NEVER", 3, unknown.data(), size));
  EXPECT_FALSE(csv.add("NEVER", 4, tiny.data(), 3));
  EXPECT_FALSE(csv.add("NEVER", 5, nullptr, 0));
  EXPECT_FALSE(ChannelCsv::type_name(good.data(), size - 1).has_value());
  EXPECT_FALSE(ChannelCsv::type_name(longer.data(), size + 1).has_value());
  EXPECT_FALSE(ChannelCsv::type_name(unknown.data(), size).has_value());
  EXPECT_FALSE(ChannelCsv::type_name(tiny.data(), 3).has_value());
  EXPECT_TRUE(csv.files().empty());
  EXPECT_FALSE(std::filesystem::exists(temp.path + "/NEVER.csv"));

  // On a channel that has a file: refused bytes add no row, nor does another type.
  ASSERT_TRUE(csv.add("OBJECT_POSITION", 10, good.data(), size));
  EXPECT_FALSE(csv.add("OBJECT_POSITION", 11, good.data(), size - 1));
  EXPECT_FALSE(csv.add("OBJECT_POSITION", 12, unknown.data(), size));
  stereograsp::grasp_command_t command{};
  const std::vector<uint8_t> other = bytes_of(command);
  EXPECT_FALSE(csv.add("OBJECT_POSITION", 13, other.data(), static_cast<int>(other.size())));
  csv.flush();
  const std::string text = test::read_text(temp.path + "/OBJECT_POSITION.csv");
  EXPECT_EQ(test::count_lines(text), 2);
  EXPECT_EQ(text.find("\n11,"), std::string::npos);

  // A stream writer refuses the same way and writes nothing at all.
  CsvWriter writer;
  std::ostringstream out;
  EXPECT_FALSE(writer.write(out, 1, unknown.data(), size));
  EXPECT_FALSE(writer.write(out, 1, good.data(), size - 1));
  EXPECT_EQ(out.str(), "");
  EXPECT_EQ(writer.rows(), 0);
}

// Doubles read back from the CSV text bit for bit (except NaN's sign and payload).
TEST(CsvWriter, DoublesRoundTripThroughText) {
  const double values[] = {0.1,
                           1.0 / 3.0,
                           M_PI,
                           -0.0,
                           std::numeric_limits<double>::denorm_min(),
                           std::numeric_limits<double>::max(),
                           -std::numeric_limits<double>::infinity(),
                           123456789.123456789,
                           kNaN};
  CsvWriter writer;
  std::ostringstream out;
  for (double v : values) {
    stereograsp::point3_t p = sample_point();
    p.position[1] = v;
    const std::vector<uint8_t> bytes = bytes_of(p);
    ASSERT_TRUE(writer.write(out, 0, bytes.data(), static_cast<int>(bytes.size())));
  }
  const auto rows = parse_csv(out.str());
  ASSERT_EQ(rows.size(), std::size(values) + 1);
  ASSERT_EQ(rows[0][4], "position_1");
  for (size_t i = 0; i < std::size(values); ++i) {
    const double back = std::strtod(rows[i + 1][4].c_str(), nullptr);
    if (std::isnan(values[i])) {
      EXPECT_EQ(rows[i + 1][4], "nan");
      EXPECT_TRUE(std::isnan(back));
    } else {
      EXPECT_EQ(std::memcmp(&back, &values[i], sizeof back), 0)
          << rows[i + 1][4] << " for " << values[i];
    }
  }
}

// The expected columns of a message, from the tests' own field list (tests/support): arrays
// flattened with _i, image bytes left out; with the value each cell must read back as.
struct Leaf {
  std::string name;
  enum { kInteger, kDouble, kString } kind;
  int64_t integer = 0;
  double real = 0;
  std::string text;
};

struct Leaves {
  template <class T>
  void add(const std::string& name, const T& value) {
    if constexpr (std::is_same_v<T, double>) {
      leaves.push_back({name, Leaf::kDouble, 0, value, ""});
    } else if constexpr (std::is_integral_v<T>) {
      leaves.push_back({name, Leaf::kInteger, static_cast<int64_t>(value), 0, ""});
    } else if constexpr (std::is_same_v<T, std::string>) {
      leaves.push_back({name, Leaf::kString, 0, 0, value});
    } else if constexpr (std::is_same_v<T, std::vector<uint8_t>>) {
      // image_t.data: not a column
    } else if constexpr (std::is_array_v<T>) {
      for (size_t i = 0; i < std::extent_v<T>; ++i) add(name + "_" + std::to_string(i), value[i]);
    } else {
      for (size_t i = 0; i < value.size(); ++i) add(name + "_" + std::to_string(i), value[i]);
    }
  }
  std::vector<Leaf> leaves;
};

template <class T>
void expect_round_trip(test::SampleKind kind) {
  T message = test::make_sample<T>(kind);
  const std::vector<uint8_t> bytes = encode_message(message);
  EXPECT_EQ(ChannelCsv::type_name(bytes.data(), static_cast<int>(bytes.size())), T::getTypeName());
  CsvWriter writer;
  std::ostringstream out;
  ASSERT_TRUE(writer.write(out, -42, bytes.data(), static_cast<int>(bytes.size())))
      << T::getTypeName();
  Leaves expected;
  sg::visit_fields(message, expected);
  const auto rows = parse_csv(out.str());
  ASSERT_EQ(rows.size(), 2u) << T::getTypeName();
  ASSERT_EQ(rows[0].size(), expected.leaves.size() + 1) << T::getTypeName();
  ASSERT_EQ(rows[1].size(), rows[0].size()) << T::getTypeName();
  EXPECT_EQ(rows[0][0], "recv_utime");
  EXPECT_EQ(rows[1][0], "-42");
  int mismatches = 0;
  for (size_t i = 0; i < expected.leaves.size(); ++i) {
    const Leaf& leaf = expected.leaves[i];
    const std::string& name = rows[0][i + 1];
    const std::string& cell = rows[1][i + 1];
    bool same = name == leaf.name;
    if (leaf.kind == Leaf::kInteger) {
      same = same && cell == std::to_string(leaf.integer);
    } else if (leaf.kind == Leaf::kString) {
      same = same && cell == leaf.text;
    } else {
      const double back = std::strtod(cell.c_str(), nullptr);
      same = same && (std::isnan(leaf.real) ? std::isnan(back) && cell == "nan"
                                            : std::memcmp(&back, &leaf.real, sizeof back) == 0);
    }
    if (!same && ++mismatches <= 5) {
      ADD_FAILURE() << T::getTypeName() << " column " << i + 1 << ": " << name << "=" << cell
                    << ", expected " << leaf.name;
    }
  }
  EXPECT_EQ(mismatches, 0) << T::getTypeName();
}

// Every field of every type, in empty, typical and extreme samples, reads back exactly.
TEST(CsvWriter, EveryTypeEveryFieldRoundTrips) {
  for (test::SampleKind kind :
       {test::SampleKind::kEmpty, test::SampleKind::kTypical, test::SampleKind::kExtreme}) {
    for_each_message_type([&]<class T>() { expect_round_trip<T>(kind); });
  }
  EXPECT_FALSE(HasFailure());
}

// A trajectory with another num_points is written under the first one's columns, and counted.
TEST(CsvWriter, TrajectoryLengthChangesKeepTheHeader) {
  CsvWriter writer;
  std::ostringstream out;
  for (int n : {2, 3, 1}) {
    stereograsp::trajectory_t t{};
    t.utime = n;
    t.num_points = n;
    t.position.assign(n, std::vector<double>{1.5, 2.5, 3.5});
    t.position_sigma.assign(n, std::vector<double>{0.5, 0.25, 0.125});
    const std::vector<uint8_t> bytes = encode_message(t);
    ASSERT_TRUE(writer.write(out, n, bytes.data(), static_cast<int>(bytes.size())));
  }
  EXPECT_EQ(writer.rows(), 3);
  EXPECT_EQ(writer.misaligned_rows(), 2);
  const auto rows = parse_csv(out.str());
  ASSERT_EQ(rows.size(), 4u);
  for (const auto& row : rows) EXPECT_EQ(row.size(), 22u);  // 2 points and 2 sigmas of 3
  EXPECT_EQ(rows[2][17], "0.125");                          // position_sigma_1_2
  EXPECT_EQ(rows[2][5], "3");                               // num_points tells the truth
  EXPECT_EQ(rows[2][11], "3.5");                            // position_1_2
  EXPECT_EQ(rows[3][9], "");  // position_1_0 of the one-point trajectory
  EXPECT_EQ(rows[3][6], "1.5");
}

// File names: unsafe characters become '_', and channels that clash get distinct files.
TEST(ChannelCsv, FileNames) {
  EXPECT_EQ(ChannelCsv::file_name("BLOB_LEFT"), "BLOB_LEFT.csv");
  EXPECT_EQ(ChannelCsv::file_name("a/b c"), "a_b_c.csv");
  EXPECT_EQ(ChannelCsv::file_name(".."), "_.csv");
  EXPECT_EQ(ChannelCsv::file_name(""), "_.csv");
  const TempDir temp;
  ChannelCsv csv(temp.path);
  const std::vector<uint8_t> bytes = bytes_of(sample_point());
  ASSERT_TRUE(csv.add("A/B", 1, bytes.data(), static_cast<int>(bytes.size())));
  ASSERT_TRUE(csv.add("A_B", 2, bytes.data(), static_cast<int>(bytes.size())));
  EXPECT_EQ(csv.files(),
            (std::vector<std::string>{temp.path + "/A_B.csv", temp.path + "/A_B.2.csv"}));
}

}  // namespace
}  // namespace sg::logger
