/// @file tools_test_support.h
/// @brief Helpers of the tools library's file tests (test_calibration_file,
/// test_estimates_csv_and_evaluation): reading and writing a text file, an exception's message,
/// and random extrinsics parameters.
#pragma once

#include <fstream>
#include <functional>
#include <initializer_list>
#include <random>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "online_stereo_calibration/core/geometry/pose.h"

namespace osc {

inline std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

inline void writeText(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

/// Expects @p fn to throw an exception of type E whose message contains every fragment.
template <typename E>
void expectThrowMentioning(const std::function<void()>& fn,
                           std::initializer_list<std::string> fragments) {
  try {
    fn();
    ADD_FAILURE() << "expected an exception mentioning " << *fragments.begin();
  } catch (const E& e) {
    const std::string message = e.what();
    for (const std::string& fragment : fragments) {
      EXPECT_NE(message.find(fragment), std::string::npos)
          << "'" << fragment << "' not in: " << message;
    }
  }
}

/// Random parameters in the RPY chart's regular region (|pitch| < pi/2).
inline Vector12d randomParameters(std::mt19937& rng) {
  std::uniform_real_distribution<double> metres(-3.0, 3.0);
  std::uniform_real_distribution<double> angle(-3.1, 3.1);
  std::uniform_real_distribution<double> pitch(-1.5, 1.5);
  Vector12d p;
  for (int block = 0; block < 2; ++block) {
    p.segment<3>(6 * block) << metres(rng), metres(rng), metres(rng);
    p.segment<3>(6 * block + 3) << angle(rng), pitch(rng), angle(rng);
  }
  return p;
}

}  // namespace osc
