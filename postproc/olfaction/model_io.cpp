#include "postproc/olfaction/model_io.h"

#include <yaml-cpp/yaml.h>

#include <fstream>

#include "core/error.h"

namespace naris::olfaction {

void write_model(const std::filesystem::path& path, const OeModel& m, const std::string& comment) {
  YAML::Emitter out;
  if (!comment.empty()) out << YAML::Comment(comment);
  out << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << m.name;
  out << YAML::Key << "sample_rate_hz" << YAML::Value << m.sample_rate;
  out << YAML::Key << "input_unit" << YAML::Value << m.input_unit;
  out << YAML::Key << "output_unit" << YAML::Value << m.output_unit;
  out << YAML::Key << "na" << YAML::Value << m.na();
  out << YAML::Key << "nb" << YAML::Value << m.nb();
  out << YAML::Key << "nd" << YAML::Value << m.nd;
  out << YAML::Key << "a" << YAML::Value << YAML::Flow << m.a;
  out << YAML::Key << "b" << YAML::Value << YAML::Flow << m.b;
  out << YAML::Key << "stable" << YAML::Value << is_stable(m);
  out << YAML::Key << "spectral_radius" << YAML::Value << spectral_radius(m);
  out << YAML::EndMap;
  std::ofstream file(path);
  if (!file) fail("{}: cannot write the model", path.string());
  file << out.c_str() << "\n";
  if (!file) fail("{}: write failed", path.string());
}

OeModel read_model(const std::filesystem::path& path) {
  YAML::Node node;
  try {
    node = YAML::LoadFile(path.string());
  } catch (const YAML::Exception& e) {
    fail("{}: cannot read the model: {}", path.string(), e.what());
  }
  OeModel m;
  try {
    m.name = node["name"] ? node["name"].as<std::string>() : path.stem().string();
    m.sample_rate = node["sample_rate_hz"] ? node["sample_rate_hz"].as<double>() : 200.0;
    m.input_unit = node["input_unit"] ? node["input_unit"].as<std::string>() : "mM";
    m.output_unit = node["output_unit"] ? node["output_unit"].as<std::string>() : "a.u.";
    m.nd = node["nd"].as<int>();
    m.a = node["a"].as<std::vector<double>>();
    m.b = node["b"].as<std::vector<double>>();
  } catch (const YAML::Exception& e) {
    fail("{}: a model needs nd, a and b ({})", path.string(), e.what());
  }
  if (node["na"] && node["na"].as<int>() != m.na())
    fail("{}: na = {} but a lists {} coefficients", path.string(), node["na"].as<int>(), m.na());
  if (node["nb"] && node["nb"].as<int>() != m.nb())
    fail("{}: nb = {} but b lists {} coefficients", path.string(), node["nb"].as<int>(), m.nb());
  if (m.nb() < 1 || m.nd < 0 || !(m.sample_rate > 0.0))
    fail("{}: need nb ≥ 1, nd ≥ 0 and a positive sample rate", path.string());
  for (double v : m.a)
    if (!std::isfinite(v)) fail("{}: non-finite coefficient in a", path.string());
  for (double v : m.b)
    if (!std::isfinite(v)) fail("{}: non-finite coefficient in b", path.string());
  return m;
}

OeModel load_model(const std::string& name_or_path) {
  if (std::filesystem::exists(name_or_path)) return read_model(name_or_path);
  return preset(name_or_path);
}

Record preprocess(const Record& r, double cutoff_hz, double rate_hz) {
  const double rate = r.sample_rate();
  Record filtered = r;
  if (rate > 2.0 * cutoff_hz * 1.05) filtered.y = bessel_lowpass(r.y, cutoff_hz, rate);
  return std::abs(rate - rate_hz) < 1e-9 * rate_hz ? filtered : resample(filtered, rate_hz);
}

}  // namespace naris::olfaction
