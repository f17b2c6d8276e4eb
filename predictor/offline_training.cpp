#include "predictor/offline_training.hpp"

#include <yaml-cpp/yaml.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <sstream>
#include <stdexcept>

#include "common/safe_decode.hpp"
#include "logger/log_reader.hpp"
#include "predictor/burg.hpp"
#include "stereograsp/point3_t.hpp"

namespace sg::predictor {

std::vector<Measurement> read_training_csv(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw std::runtime_error(path + ": cannot open");
  std::vector<Measurement> out;
  std::string line;
  for (int number = 1; std::getline(file, line); ++number) {
    if (line.empty() || line[0] == '#' ||
        !(std::isdigit(static_cast<unsigned char>(line[0])) || line[0] == '-'))
      continue;  // a header or a comment
    std::stringstream s(line);
    double t, x, y, z;
    char c1, c2, c3;
    std::string rest;
    if (!(s >> t >> c1 >> x >> c2 >> y >> c3 >> z) || c1 != ',' || c2 != ',' || c3 != ',' ||
        (s >> rest) || !std::isfinite(t) || !std::isfinite(x) || !std::isfinite(y) ||
        !std::isfinite(z))
      throw std::runtime_error(path + ":" + std::to_string(number) + ": expected t,x,y,z");
    const int64_t utime = t > 1e12 ? static_cast<int64_t>(t) : std::llround(t * 1e6);
    out.push_back({utime, true, {x, y, z}});
  }
  return out;
}

std::vector<Measurement> read_training_log(const std::string& path, const std::string& channel) {
  // sg::logger::LogReader, not lcm::LogFile: LCM's reader crashes on a damaged event length.
  std::unique_ptr<logger::LogReader> log;
  try {
    log = std::make_unique<logger::LogReader>(path);
  } catch (const logger::LogReadError& e) {
    throw std::runtime_error(std::string(e.what()) + " (or give a .csv)");
  }
  std::vector<Measurement> out;
  logger::LogRecord e;
  while (log->next(e)) {
    if (e.channel != channel) continue;
    stereograsp::point3_t p{};
    if (!sg::safe_decode(e.data, e.size, p) || !p.visible) continue;
    out.push_back({p.utime, true, {p.position[0], p.position[1], p.position[2]}});
  }
  return out;
}

TrainedCoefficients train_coefficients(const std::vector<Measurement>& measurements,
                                       const PredictorParams& params) {
  PredictorParams resampling = params;
  resampling.model = Model::kHold;  // only to resample onto the period
  TrajectoryPredictor resampler(resampling);
  std::array<std::vector<double>, 3> series;
  for (const Measurement& m : measurements) {
    for (const Forecast& f : resampler.add(m)) {
      if (f.status != TrackStatus::kTracking) continue;
      for (size_t i = 0; i < 3; ++i) series[i].push_back(f.sample[static_cast<int>(i)]);
    }
  }
  TrainedCoefficients t;
  t.order = params.burg.order;
  t.period = static_cast<double>(params.period_us) * 1e-6;
  t.samples = static_cast<int>(series[0].size());
  if (t.samples < 2 * t.order + 3) {
    throw std::runtime_error(std::to_string(t.samples) + " samples at the period; need at least " +
                             std::to_string(2 * t.order + 3));
  }
  for (size_t i = 0; i < 3; ++i) {
    std::vector<double>& x = series[i];
    double mean = 0;
    for (double v : x) mean += v;
    mean /= t.samples;
    for (double& v : x) v -= mean;
    const BurgResult b = burg(x.data(), t.samples, t.order);
    t.coefficients[i] = b.coefficients;
    t.error_power[i] = b.error_power;
  }
  return t;
}

void write_coefficients(const std::string& path, const TrainedCoefficients& t,
                        const std::string& source) {
  YAML::Emitter yaml;
  yaml << YAML::BeginMap << YAML::Key << "order" << YAML::Value << t.order << YAML::Key << "period"
       << YAML::Value << t.period << YAML::Key << "samples" << YAML::Value << t.samples << YAML::Key
       << "source" << YAML::Value << source << YAML::Key << "coefficients" << YAML::Value
       << YAML::BeginMap;
  const char* axes[3] = {"x", "y", "z"};
  for (size_t i = 0; i < 3; ++i) {
    yaml << YAML::Key << axes[i] << YAML::Value << YAML::Flow << YAML::Precision(17)
         << t.coefficients[i];
  }
  yaml << YAML::EndMap << YAML::EndMap;
  const std::string temporary = path + ".tmp";
  std::ofstream file(temporary);
  file << "# trained by: sg-predictor train " << source << "\n" << yaml.c_str() << "\n";
  file.close();
  if (!file || std::rename(temporary.c_str(), path.c_str()) != 0)
    throw std::runtime_error(path + ": cannot write");
}

}  // namespace sg::predictor
