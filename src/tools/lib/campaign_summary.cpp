#include "online_stereo_calibration/tools/campaign_summary.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>

#include "online_stereo_calibration/tools/campaign_score.h"
#include "online_stereo_calibration/tools/perfect_filter.h"

namespace osc {

namespace {

bool parseNumber(const std::string& text, double* value) {
  if (text.empty()) return false;
  char* end = nullptr;
  *value = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size() && std::isfinite(*value);
}

std::string format(const char* pattern, double value) {
  char text[64];
  std::snprintf(text, sizeof(text), pattern, value);
  return text;
}

const std::string* settingOf(const CampaignRow& row, const std::string& name) {
  for (const auto& [n, v] : row.settings) {
    if (n == name) return &v;
  }
  return nullptr;
}

/// Not honest before honest, failed first, then descending max_z.
bool worse(const CampaignRow& a, const CampaignRow& b) {
  if (a.ok() != b.ok()) return !a.ok();
  if (a.honest() != b.honest()) return !a.honest();
  return a.score.max_z > b.score.max_z;
}

double median(std::vector<double> values) {
  values.erase(std::remove_if(values.begin(), values.end(), [](double v) { return std::isnan(v); }),
               values.end());
  if (values.empty()) return NAN;
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

std::string percent(int part, int whole) {
  return whole == 0 ? "-" : format("%.0f %%", 100.0 * part / whole);
}

}  // namespace

std::vector<CampaignBucket> campaignBuckets(const std::vector<CampaignRow>& rows,
                                            const std::string& name) {
  std::set<double> distinct;
  for (const CampaignRow& row : rows) {
    double v;
    const std::string* text = settingOf(row, name);
    if (text && parseNumber(*text, &v)) distinct.insert(v);
  }
  const bool intervals = distinct.size() > 3;
  const double low = intervals ? *distinct.begin() : 0.0;
  const double high = intervals ? *distinct.rbegin() : 0.0;
  std::map<std::string, CampaignBucket> by_label;
  std::vector<std::string> order;
  std::vector<CampaignBucket> numeric(intervals ? 3 : 0);
  for (int b = 0; b < static_cast<int>(numeric.size()); ++b) {
    const double a = low + (high - low) * b / 3.0, z = low + (high - low) * (b + 1) / 3.0;
    numeric[b].label = "[" + format("%.3g", a) + ", " + format("%.3g", z) + (b == 2 ? "]" : ")");
  }
  for (int i = 0; i < static_cast<int>(rows.size()); ++i) {
    const std::string* text = settingOf(rows[i], name);
    const std::string value = text ? *text : "";
    double v;
    if (intervals && parseNumber(value, &v)) {
      const int b = std::min(2, static_cast<int>((v - low) / (high - low) * 3.0));
      numeric[std::max(0, b)].rows.push_back(i);
      continue;
    }
    const std::string label = value.empty() ? "(none)" : value;
    if (!by_label.count(label)) {
      order.push_back(label);
      by_label[label].label = label;
    }
    by_label[label].rows.push_back(i);
  }
  std::vector<CampaignBucket> buckets;
  for (const CampaignBucket& b : numeric) {
    if (!b.rows.empty()) buckets.push_back(b);
  }
  std::sort(order.begin(), order.end(), [](const std::string& a, const std::string& b) {
    double x, y;
    if (parseNumber(a, &x) && parseNumber(b, &y)) return x < y;
    return a < b;
  });
  for (const std::string& label : order) buckets.push_back(by_label[label]);
  return buckets;
}

std::array<ParameterBias, 12> campaignParameterBias(const std::vector<CampaignRow>& rows) {
  std::array<ParameterBias, 12> bias;
  for (int p = 0; p < 12; ++p) {
    std::vector<double> means;
    for (const CampaignRow& row : rows) {
      if (row.ok() && std::isfinite(row.score.mean_z[p])) means.push_back(row.score.mean_z[p]);
    }
    ParameterBias& b = bias[p];
    b.runs = static_cast<int>(means.size());
    b.standard_error = NAN;
    b.mean = NAN;
    if (means.empty()) continue;
    double sum = 0.0;
    for (double m : means) sum += m;
    b.mean = sum / b.runs;
    if (b.runs < 2) continue;
    double square_sum = 0.0;
    for (double m : means) square_sum += (m - b.mean) * (m - b.mean);
    b.standard_error = std::sqrt(square_sum / (b.runs - 1) / b.runs);
  }
  return bias;
}

std::string formatCampaignSummary(const std::vector<CampaignRow>& rows, int worst) {
  std::ostringstream text;
  int ok = 0, honest = 0;
  int runs_beyond = 0, frames_beyond = 0, runs_unseen = 0, frames_unseen = 0;
  int frames_converged = 0, frames_converged_off = 0, runs_converged_off = 0;
  std::vector<double> shares, max_z, nees, times, converged;
  for (const CampaignRow& row : rows) {
    ok += row.ok();
    honest += row.honest();
    if (!row.ok()) continue;
    runs_beyond += row.score.frames_beyond_5sigma > 0;
    frames_beyond += row.score.frames_beyond_5sigma;
    runs_unseen += row.score.frames_beyond_5sigma_unseen > 0;
    frames_unseen += row.score.frames_beyond_5sigma_unseen;
    shares.push_back(row.score.share_within_3sigma);
    max_z.push_back(row.score.max_z);
    nees.push_back(row.score.nees_mean);
    times.push_back(row.score.time_ms_median);
    if (row.score.converged_frame >= 0) converged.push_back(row.score.converged_frame);
    frames_converged += row.score.frames_converged;
    frames_converged_off += row.score.frames_converged_beyond_3sigma;
    runs_converged_off += row.score.frames_converged_beyond_3sigma > 0;
  }
  const int n = static_cast<int>(rows.size());
  text << "Campaign of " << n << " runs (" << ok << " ran, " << n - ok << " failed)\n"
       << "Honest (share_within_3sigma >= " << kHonestShare
       << " and frames_beyond_5sigma = 0): " << honest << " of " << n << " (" << percent(honest, n)
       << ")\n";
  if (n > 0 && rows.front().frames > kCampaignFirstScoredFrame) {
    const PerfectFilterScore perfect = perfectFilterScore(rows.front().frames);
    text << "A perfect filter (its errors exactly N(0, sigma), perfect_filter.h) on runs of "
         << rows.front().frames << " frames: honest in "
         << format("%.0f", 100.0 * perfect.honest_low) << "-"
         << format("%.0f %%", 100.0 * perfect.honest_high)
         << " of the runs, some frame beyond 5 sigma in "
         << format("%.1f %%", 100.0 * perfect.beyond_5sigma) << ", mean share within 3 sigma "
         << format("%.3f", perfect.mean_share) << ", CONVERGED frames beyond 3 sigma about 3 %\n";
  }
  text << "Frames beyond 5 sigma: " << frames_beyond << " in " << runs_beyond << " runs; of them "
       << frames_unseen << " in " << runs_unseen
       << " runs in an unseen change (frames_beyond_5sigma_unseen: the calibration changed in a "
          "blind stretch, nothing tracked since)\n"
       << "Medians over the runs that ran: share_within_3sigma " << format("%.3f", median(shares))
       << ", max_z " << format("%.2f", median(max_z)) << ", nees_mean "
       << format("%.2f", median(nees)) << ", time per frame " << format("%.2f", median(times))
       << " ms\n"
       << "Converged (CONVERGED state reached): " << converged.size() << " of " << ok
       << " runs, median at frame " << format("%.0f", median(converged)) << "; " << frames_converged
       << " frames CONVERGED, of them " << frames_converged_off << " ("
       << (frames_converged == 0
               ? "-"
               : format("%.1f %%", 100.0 * frames_converged_off / frames_converged))
       << ") in " << runs_converged_off
       << " runs with some error beyond 3 sigma (about 3 % when honest)\n";
  const std::array<ParameterBias, 12> bias = campaignParameterBias(rows);
  text << "Mean signed error / sigma from frame 30, over the runs +- its standard error (a "
          "consistent filter: 0 within about 2; * beyond 3, biased to that side):\n ";
  for (int p = 0; p < 12; ++p) {
    text << " " << campaignParameterNames()[p] << " " << format("%+.2f", bias[p].mean) << " +- "
         << format("%.2f", bias[p].standard_error) << (bias[p].significant() ? "*" : "")
         << (p == 5 ? "\n " : "");
  }
  text << "\n\n";

  std::vector<int> order(rows.size());
  for (int i = 0; i < n; ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return worse(rows[a], rows[b]); });
  text << "Worst runs (failed, then not honest, then by max_z); replay one with --only RUN:\n";
  for (int k = 0; k < std::min(worst, n); ++k) {
    const CampaignRow& row = rows[order[k]];
    text << "  run " << row.run << "  seed " << row.seed << "  "
         << (row.ok() ? (row.honest() ? "honest" : "NOT honest") : row.status)
         << "  share_within_3sigma " << format("%.3f", row.score.share_within_3sigma)
         << "  frames_beyond_5sigma " << row.score.frames_beyond_5sigma << " (unseen "
         << row.score.frames_beyond_5sigma_unseen << ")  max_z " << format("%.2f", row.score.max_z)
         << " (" << row.score.max_z_parameter << ")"
         << "  nees_mean " << format("%.2f", row.score.nees_mean) << "\n    ";
    for (const auto& [name, value] : row.settings) text << name << "=" << value << " ";
    text << "\n";
  }

  std::vector<std::string> names;
  for (const CampaignRow& row : rows) {
    if (row.settings.size() > names.size()) {
      names.clear();
      for (const auto& nv : row.settings) names.push_back(nv.first);
    }
  }
  text << "\nBy setting (bucket: runs, honest share, median and worst max_z with its run):\n";
  for (const std::string& name : names) {
    text << "  " << name << "\n";
    for (const CampaignBucket& bucket : campaignBuckets(rows, name)) {
      int h = 0;
      std::vector<double> z;
      int worst_row = bucket.rows.front();
      for (int i : bucket.rows) {
        h += rows[i].honest();
        z.push_back(rows[i].score.max_z);
        if (worse(rows[i], rows[worst_row])) worst_row = i;
      }
      char line[256];
      std::snprintf(line, sizeof(line),
                    "    %-24s %4zu runs  honest %5s  max_z median %7.2f  worst %7.2f (run %d)\n",
                    bucket.label.c_str(), bucket.rows.size(),
                    percent(h, static_cast<int>(bucket.rows.size())).c_str(), median(z),
                    rows[worst_row].score.max_z, rows[worst_row].run);
      text << line;
    }
  }
  return text.str();
}

}  // namespace osc
