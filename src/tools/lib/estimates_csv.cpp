#include "online_stereo_calibration/tools/estimates_csv.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <locale>
#include <sstream>
#include <stdexcept>

#include "online_stereo_calibration/core/sim/scenario_runner.h"
#include "online_stereo_calibration/tools/calibration_file.h"

namespace osc {
namespace {

const char* const kParameterNames[12] = {"xl", "yl", "zl", "roll_l", "pitch_l", "yaw_l",
                                         "xr", "yr", "zr", "roll_r", "pitch_r", "yaw_r"};

std::string join(const std::vector<std::string>& columns) {
  std::string text;
  for (std::size_t i = 0; i < columns.size(); ++i) {
    if (i > 0) text += ',';
    text += columns[i];
  }
  return text;
}

/// 17 significant digits, locale-independent ("nan"/"inf" for non-finite values).
std::string formatValue(double value) {
  std::ostringstream out;
  out.imbue(std::locale::classic());
  out.precision(17);
  out << value;
  return out.str();
}

bool parseDouble(const std::string& field, double* value) {
  std::string lower(field);
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  const bool negative = !lower.empty() && lower[0] == '-';
  const std::string body =
      (!lower.empty() && (lower[0] == '-' || lower[0] == '+')) ? lower.substr(1) : lower;
  if (body == "nan") {
    *value = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  if (body == "inf" || body == "infinity") {
    *value = negative ? -std::numeric_limits<double>::infinity()
                      : std::numeric_limits<double>::infinity();
    return true;
  }
  std::istringstream in(field);
  in.imbue(std::locale::classic());
  in >> *value;
  return !in.fail() && (in >> std::ws).eof();
}

bool parseInt(const std::string& field, int* value) {
  std::istringstream in(field);
  in.imbue(std::locale::classic());
  in >> *value;
  return !in.fail() && (in >> std::ws).eof();
}

/// Stamp with at least 9 decimals, more if needed for the same double to be read back.
std::string formatStamp(double stamp) {
  if (!std::isfinite(stamp)) return formatValue(stamp);
  std::string text;
  for (int decimals = 9; decimals <= 40; ++decimals) {
    std::ostringstream out;
    out.imbue(std::locale::classic());
    out.setf(std::ios::fixed, std::ios::floatfield);
    out.precision(decimals);
    out << stamp;
    text = out.str();
    double back = 0.0;
    if (parseDouble(text, &back) && back == stamp) break;
  }
  return text;
}

void openForWriting(std::ofstream& out, const std::string& path, const std::string& header) {
  out.open(path, std::ios::out | std::ios::trunc);
  if (!out) throw std::runtime_error("CSV file '" + path + "': cannot open for writing");
  out << header << '\n';
}

void checkStream(const std::ofstream& out, const std::string& path) {
  if (!out) throw std::runtime_error("CSV file '" + path + "': write error");
}

/// Reads a CSV whose header starts with @p columns; calls @p row_fn(fields, line_number).
template <typename RowFn>
void readCsv(const std::string& path, const std::vector<std::string>& columns, RowFn row_fn) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("CSV file '" + path + "': cannot open for reading");
  const auto fail = [&path](int line, const std::string& what) {
    throw std::runtime_error("CSV file '" + path + "', line " + std::to_string(line) + ": " + what);
  };
  std::string line;
  int line_number = 0;
  std::vector<std::string> fields;
  const auto split = [&fields](const std::string& text) {
    fields.clear();
    std::size_t start = 0;
    while (true) {
      const std::size_t comma = text.find(',', start);
      fields.push_back(text.substr(start, comma - start));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
  };
  const auto strip = [](std::string& text) {
    if (!text.empty() && text.back() == '\r') text.pop_back();
  };

  if (!std::getline(in, line)) fail(1, "empty file, expected header '" + join(columns) + "'");
  ++line_number;
  strip(line);
  split(line);
  if (fields.size() < columns.size() ||
      !std::equal(columns.begin(), columns.end(), fields.begin())) {
    fail(1, "header must start with '" + join(columns) + "'");
  }
  while (std::getline(in, line)) {
    ++line_number;
    strip(line);
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    split(line);
    if (fields.size() < columns.size()) {
      fail(line_number, "expected " + std::to_string(columns.size()) + " fields, found " +
                            std::to_string(fields.size()));
    }
    row_fn(fields, line_number, fail);
  }
  if (in.bad()) fail(line_number, "read error");
}

template <typename Fail>
double field(const std::vector<std::string>& fields, const std::vector<std::string>& columns,
             std::size_t index, int line, const Fail& fail) {
  double value = 0.0;
  if (!parseDouble(fields[index], &value)) {
    fail(line, "column '" + columns[index] + "' is not a number: '" + fields[index] + "'");
  }
  return value;
}

template <typename Fail>
int intField(const std::vector<std::string>& fields, const std::vector<std::string>& columns,
             std::size_t index, int line, const Fail& fail) {
  int value = 0;
  if (!parseInt(fields[index], &value)) {
    fail(line, "column '" + columns[index] + "' is not an integer: '" + fields[index] + "'");
  }
  return value;
}

}  // namespace

const std::vector<std::string>& estimatesCsvColumns() {
  static const std::vector<std::string> columns = [] {
    std::vector<std::string> c = {"frame", "stamp"};
    for (const char* name : kParameterNames) c.emplace_back(name);
    for (const char* name : kParameterNames) c.push_back(std::string("sigma_") + name);
    c.emplace_back("tracked_points");
    c.emplace_back("time_ms");
    return c;
  }();
  return columns;
}

EstimateRow estimateRowOf(const ScenarioFrameResult& result) {
  EstimateRow row;
  row.frame = result.frame;
  row.stamp = result.stamp;
  row.parameters = result.parameters;
  row.sigmas = result.sigmas;
  row.tracked_points = result.tracked_points;
  row.time_ms = result.time_ms;
  row.time_offset = result.time_offset;
  row.time_offset_sigma = result.time_offset_sigma;
  return row;
}

ReferenceRow referenceRowOf(const ScenarioFrameResult& result) {
  ReferenceRow row;
  row.frame = result.frame;
  row.stamp = result.stamp;
  row.parameters = result.truth;
  return row;
}

CalibrationFile calibrationFileOf(const EstimateRow& row) {
  CalibrationFile file;
  file.extrinsics = StereoExtrinsics::fromParameters(row.parameters);
  file.sigmas = row.sigmas;
  file.stamp = row.stamp;
  if (row.time_offset_sigma > 0.0) {
    file.time_offset = row.time_offset;
    file.time_offset_sigma = row.time_offset_sigma;
  }
  return file;
}

const std::vector<std::string>& estimatesCsvFurtherColumns() {
  static const std::vector<std::string> columns = {"time_offset_ms", "sigma_time_offset_ms"};
  return columns;
}

const std::vector<std::string>& referenceCsvColumns() {
  static const std::vector<std::string> columns = [] {
    std::vector<std::string> c = {"frame", "stamp"};
    for (const char* name : kParameterNames) c.emplace_back(name);
    return c;
  }();
  return columns;
}

std::string estimatesCsvHeader() {
  return join(estimatesCsvColumns()) + ',' + join(estimatesCsvFurtherColumns());
}

std::string referenceCsvHeader() { return join(referenceCsvColumns()); }

EstimatesCsvWriter::EstimatesCsvWriter(const std::string& path) : path_(path) {
  openForWriting(out_, path_, estimatesCsvHeader());
}

void EstimatesCsvWriter::write(const EstimateRow& row) {
  out_ << row.frame << ',' << formatStamp(row.stamp);
  for (int i = 0; i < 12; ++i) out_ << ',' << formatValue(row.parameters(i));
  for (int i = 0; i < 12; ++i) out_ << ',' << formatValue(row.sigmas(i));
  out_ << ',' << row.tracked_points << ',' << formatValue(row.time_ms) << ','
       << formatValue(row.time_offset * 1e3) << ',' << formatValue(row.time_offset_sigma * 1e3)
       << '\n';
  checkStream(out_, path_);
}

void EstimatesCsvWriter::flush() {
  out_.flush();
  checkStream(out_, path_);
}

ReferenceCsvWriter::ReferenceCsvWriter(const std::string& path) : path_(path) {
  openForWriting(out_, path_, referenceCsvHeader());
}

void ReferenceCsvWriter::write(const ReferenceRow& row) {
  out_ << row.frame << ',' << formatStamp(row.stamp);
  for (int i = 0; i < 12; ++i) out_ << ',' << formatValue(row.parameters(i));
  out_ << '\n';
  checkStream(out_, path_);
}

void ReferenceCsvWriter::flush() {
  out_.flush();
  checkStream(out_, path_);
}

std::vector<EstimateRow> readEstimatesCsv(const std::string& path) {
  const std::vector<std::string>& columns = estimatesCsvColumns();
  std::vector<EstimateRow> rows;
  readCsv(path, columns, [&](const std::vector<std::string>& f, int line, const auto& fail) {
    EstimateRow row;
    row.frame = intField(f, columns, 0, line, fail);
    row.stamp = field(f, columns, 1, line, fail);
    for (int i = 0; i < 12; ++i) row.parameters(i) = field(f, columns, 2 + i, line, fail);
    for (int i = 0; i < 12; ++i) row.sigmas(i) = field(f, columns, 14 + i, line, fail);
    row.tracked_points = intField(f, columns, 26, line, fail);
    row.time_ms = field(f, columns, 27, line, fail);
    rows.push_back(row);
  });
  return rows;
}

std::vector<ReferenceRow> readReferenceCsv(const std::string& path) {
  const std::vector<std::string>& columns = referenceCsvColumns();
  std::vector<ReferenceRow> rows;
  readCsv(path, columns, [&](const std::vector<std::string>& f, int line, const auto& fail) {
    ReferenceRow row;
    row.frame = intField(f, columns, 0, line, fail);
    row.stamp = field(f, columns, 1, line, fail);
    for (int i = 0; i < 12; ++i) row.parameters(i) = field(f, columns, 2 + i, line, fail);
    rows.push_back(row);
  });
  return rows;
}

}  // namespace osc
