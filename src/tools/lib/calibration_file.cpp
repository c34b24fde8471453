#include "online_stereo_calibration/tools/calibration_file.h"
#include "online_stereo_calibration/tools/output_directory.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <locale>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <yaml-cpp/yaml.h>
#include <Eigen/Cholesky>

namespace osc {
namespace {

constexpr const char* kVehicleToLeft = "vehicle_to_left";
constexpr const char* kLeftToRight = "left_to_right";
constexpr const char* kSigmaVehicleToLeft = "sigma_vehicle_to_left";
constexpr const char* kSigmaLeftToRight = "sigma_left_to_right";
constexpr const char* kStamp = "stamp";
constexpr const char* kTimeOffset = "time_offset";
constexpr const char* kSigmaTimeOffset = "sigma_time_offset";
constexpr const char* kCovariance = "covariance";

[[noreturn]] void fail(const std::string& source, const std::string& what) {
  throw std::runtime_error("calibration file '" + source + "': " + what);
}

/// One finite number from a YAML scalar.
double readNumber(const YAML::Node& node, const std::string& source, const std::string& key) {
  double value = 0.0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, value)) {
    fail(source, "key '" + key + "' is not a number");
  }
  if (!std::isfinite(value)) fail(source, "key '" + key + "' is NaN or infinite");
  return value;
}

/// A list of exactly 6 finite numbers.
Vector6d readVector6(const YAML::Node& root, const std::string& source, const std::string& key) {
  const YAML::Node node = root[key];
  if (!node) fail(source, "missing key '" + key + "'");
  if (!node.IsSequence() || node.size() != 6) {
    fail(source, "key '" + key + "' must be a list of 6 numbers");
  }
  Vector6d v;
  for (int i = 0; i < 6; ++i) {
    v(i) = readNumber(node[i], source, key + "[" + std::to_string(i) + "]");
  }
  return v;
}

/// The optional 12x12 covariance: 144 finite numbers, row-major, symmetric (to 1e-9 of its
/// largest entry), positive definite, and its diagonal equal to sigmas^2 (to 1e-6) if the file
/// has sigmas too (a hand-edited sigma with a stale covariance is refused, not guessed at).
Matrix12d readCovariance(const YAML::Node& root, const std::string& source,
                         const std::optional<Vector12d>& sigmas) {
  const YAML::Node node = root[kCovariance];
  if (!node.IsSequence() || node.size() != 144) {
    fail(source,
         std::string("key '") + kCovariance + "' must be a list of 144 numbers (12x12, row-major)");
  }
  Matrix12d covariance;
  for (int i = 0; i < 144; ++i) {
    covariance(i / 12, i % 12) =
        readNumber(node[i], source, std::string(kCovariance) + "[" + std::to_string(i) + "]");
  }
  const double scale = covariance.cwiseAbs().maxCoeff();
  if ((covariance - covariance.transpose()).cwiseAbs().maxCoeff() > 1e-9 * scale) {
    fail(source, std::string("key '") + kCovariance + "' is not symmetric");
  }
  if (scale == 0.0 || Eigen::LLT<Matrix12d>(covariance).info() != Eigen::Success) {
    fail(source, std::string("key '") + kCovariance + "' is not positive definite");
  }
  if (sigmas) {
    for (int i = 0; i < 12; ++i) {
      const double variance = (*sigmas)(i) * (*sigmas)(i);
      if (std::abs(covariance(i, i) - variance) > 1e-6 * std::max(variance, covariance(i, i))) {
        fail(source, std::string("key '") + kCovariance + "[" + std::to_string(13 * i) +
                         "]' (a variance) disagrees with the square of its sigma; edit or "
                         "remove '" +
                         kCovariance + "'");
      }
    }
  }
  return covariance;  // as written (bit-exact round trip); users symmetrise if they need to
}

/// A number with 17 significant digits, locale-independent, always with a '.' in the
/// mantissa so that YAML 1.1 readers (PyYAML) see a float, not a string.
std::string formatNumber(double value) {
  if (value == 0.0) value = 0.0;  // "-0.0" (from RPY extraction) reads oddly; same value
  std::ostringstream out;
  out.imbue(std::locale::classic());
  out.precision(17);
  out << value;
  std::string text = out.str();
  if (text.find_first_of(".ne") == std::string::npos) {
    text += ".0";
  } else if (text.find('.') == std::string::npos && text.find('e') != std::string::npos) {
    text.insert(text.find('e'), ".0");
  }
  return text;
}

std::string formatList(const Vector6d& v) {
  std::string text = "[";
  for (int i = 0; i < 6; ++i) {
    if (i > 0) text += ", ";
    text += formatNumber(v(i));
  }
  return text + "]";
}

}  // namespace

CalibrationFile parseCalibrationYaml(const std::string& text, const std::string& source_name) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    fail(source_name, std::string("invalid YAML: ") + e.what());
  }
  if (!root.IsMap()) fail(source_name, "expected a map with keys vehicle_to_left, left_to_right");

  CalibrationFile file;
  // Read each half before the comma initialiser: a throw inside it trips Eigen's assert.
  const Vector6d vehicle_to_left = readVector6(root, source_name, kVehicleToLeft);
  const Vector6d left_to_right = readVector6(root, source_name, kLeftToRight);
  Vector12d parameters;
  parameters << vehicle_to_left, left_to_right;
  file.extrinsics = StereoExtrinsics::fromParameters(parameters);

  const bool has_sigma_left = static_cast<bool>(root[kSigmaVehicleToLeft]);
  const bool has_sigma_right = static_cast<bool>(root[kSigmaLeftToRight]);
  if (has_sigma_left || has_sigma_right) {
    const Vector6d sigma_left = readVector6(root, source_name, kSigmaVehicleToLeft);
    const Vector6d sigma_right = readVector6(root, source_name, kSigmaLeftToRight);
    Vector12d sigmas;
    sigmas << sigma_left, sigma_right;
    for (int i = 0; i < 12; ++i) {
      if (sigmas(i) < 0.0) {
        fail(source_name, "key '" + std::string(i < 6 ? kSigmaVehicleToLeft : kSigmaLeftToRight) +
                              "[" + std::to_string(i % 6) + "]' is negative");
      }
    }
    file.sigmas = sigmas;
  }
  if (root[kStamp]) file.stamp = readNumber(root[kStamp], source_name, kStamp);
  if (root[kTimeOffset]) file.time_offset = readNumber(root[kTimeOffset], source_name, kTimeOffset);
  if (root[kSigmaTimeOffset]) {
    file.time_offset_sigma = readNumber(root[kSigmaTimeOffset], source_name, kSigmaTimeOffset);
    if (*file.time_offset_sigma < 0.0) fail(source_name, "key 'sigma_time_offset' is negative");
  }
  if (root[kCovariance]) file.covariance = readCovariance(root, source_name, file.sigmas);
  return file;
}

std::optional<Matrix12d> parameterCovariance(const CalibrationFile& file) {
  if (file.covariance) return *file.covariance;
  if (!file.sigmas) return std::nullopt;
  Matrix12d covariance = Matrix12d::Zero();
  covariance.diagonal() = file.sigmas->cwiseProduct(*file.sigmas);
  return covariance;
}

CalibrationFile readCalibrationFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("calibration file '" + path + "': cannot open for reading");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw std::runtime_error("calibration file '" + path + "': read error");
  return parseCalibrationYaml(text.str(), path);
}

std::string formatCalibrationYaml(const CalibrationFile& file) {
  const Vector12d p = file.extrinsics.toParameters();
  if (!p.allFinite() || (file.sigmas && !file.sigmas->allFinite()) ||
      (file.stamp && !std::isfinite(*file.stamp)) ||
      (file.time_offset && !std::isfinite(*file.time_offset)) ||
      (file.time_offset_sigma && !std::isfinite(*file.time_offset_sigma)) ||
      (file.covariance && !file.covariance->allFinite())) {
    throw std::runtime_error("calibration: refusing to write NaN or infinite values");
  }
  std::string text =
      "# online_stereo_calibration extrinsics; metres and radians; [x, y, z, roll, pitch, yaw], "
      "R = Rz(yaw) Ry(pitch) Rx(roll).\n"
      "# vehicle_to_left: left camera body frame (x fwd, y left, z up) in the vehicle frame "
      "(REP 103); left_to_right: right camera body frame in the left camera body frame.\n";
  text += std::string(kVehicleToLeft) + ": " + formatList(p.head<6>()) + "\n";
  text += std::string(kLeftToRight) + ": " + formatList(p.tail<6>()) + "\n";
  if (file.sigmas) {
    text += std::string(kSigmaVehicleToLeft) + ": " + formatList(file.sigmas->head<6>()) + "\n";
    text += std::string(kSigmaLeftToRight) + ": " + formatList(file.sigmas->tail<6>()) + "\n";
  }
  if (file.stamp) text += std::string(kStamp) + ": " + formatNumber(*file.stamp) + "\n";
  if (file.time_offset) {
    text += std::string(kTimeOffset) + ": " + formatNumber(*file.time_offset) +
            "  # s, camera clock minus odometry clock (estimated)\n";
  }
  if (file.time_offset_sigma)
    text += std::string(kSigmaTimeOffset) + ": " + formatNumber(*file.time_offset_sigma) + "\n";
  if (file.covariance) {
    // One flow list over 12 lines, a row of the matrix per line.
    text += std::string(kCovariance) +
            ":  # 12x12 covariance of the parameters above, row-major (m^2, m rad, rad^2)\n  [";
    for (int i = 0; i < 12; ++i) {
      for (int j = 0; j < 12; ++j) {
        text += formatNumber((*file.covariance)(i, j));
        if (j < 11) text += ", ";
      }
      text += i < 11 ? ",\n   " : "]\n";
    }
  }
  return text;
}

void writeCalibrationFileAtomic(const std::string& path, const CalibrationFile& file) {
  const std::string text = formatCalibrationYaml(file);
  try {
    writeTextFileAtomic(path, text);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error("calibration file '" + path + "': " + e.what());
  }
}

}  // namespace osc
