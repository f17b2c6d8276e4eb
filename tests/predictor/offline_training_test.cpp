// The offline trainer: a CSV in, Burg's coefficients of the same samples out; bad lines named.

#include "predictor/offline_training.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "predictor/burg.hpp"
#include "predictor/predictor_settings.hpp"
#include "tests/support/subprocess.hpp"

namespace sg::predictor {
namespace {

std::string write(const std::string& name, const std::string& text) {
  const std::string path = test::make_temp_dir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

/// x(k) of the paper's circle at 4 Hz: 0.45 + 0.15 cos(2 pi k / 240).
double circle_x(int k) { return 0.45 + 0.15 * std::cos(2 * M_PI * k / 240.0); }

// Samples on the period grid come out as the coefficients burg() gives on the same samples
// (mean removed), and the file written reads back as the predictor's initial coefficients.
TEST(OfflineTraining, CsvGivesBurgOfTheSameSamples) {
  std::string csv = "t_s,x,y,z\n# the paper's circle\n";
  const int n = 300;
  for (int k = 0; k < n; ++k) {
    csv += std::to_string(k * 0.25) + "," + std::to_string(circle_x(k)) + ",0.0,0.1\n";
  }
  const std::string path = write("circle.csv", csv);
  const auto measurements = read_training_csv(path);
  ASSERT_EQ(measurements.size(), static_cast<size_t>(n));
  PredictorParams params;
  params.burg.order = 4;
  const TrainedCoefficients t = train_coefficients(measurements, params);
  ASSERT_GE(t.samples, n - 1);
  std::vector<double> x;
  for (int k = n - t.samples; k < n; ++k) x.push_back(std::stod(std::to_string(circle_x(k))));
  double mean = 0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(x.size());
  for (double& v : x) v -= mean;
  const BurgResult expected = burg(x.data(), static_cast<int>(x.size()), 4);
  ASSERT_EQ(t.coefficients[0].size(), 4u);
  for (size_t i = 0; i < 4; ++i) EXPECT_NEAR(t.coefficients[0][i], expected.coefficients[i], 1e-9);

  const std::string out = test::make_temp_dir() + "/coefficients.yaml";
  write_coefficients(out, t, path);
  PredictorParams loaded;
  read_coefficients(out, loaded);
  EXPECT_EQ(loaded.burg.order, 4);
  for (size_t i = 0; i < 4; ++i)
    EXPECT_DOUBLE_EQ(loaded.initial_coefficients[0][i], t.coefficients[0][i]);
}

// A malformed line names the file and its line.
TEST(OfflineTraining, MalformedCsvLineNamesFileAndLine) {
  const std::string path = write("bad.csv", "t,x,y,z\n0.0,0.4,0,0.1\n0.25,0.4;0,0.1\n");
  try {
    read_training_csv(path);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), path + ":3: expected t,x,y,z");
  }
  EXPECT_THROW(read_training_csv(write("nan.csv", "0.0,nan,0,0\n")), std::runtime_error);
  EXPECT_THROW(read_training_csv("/nonexistent/positions.csv"), std::runtime_error);
}

// Too few samples for the order is refused, with how many there were and are needed.
TEST(OfflineTraining, TooFewSamplesIsRefused) {
  std::vector<Measurement> m;
  for (int k = 0; k < 10; ++k) m.push_back({k * 250'000, true, {circle_x(k), 0, 0.1}});
  PredictorParams params;
  try {
    train_coefficients(m, params);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("need at least 27"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace sg::predictor
