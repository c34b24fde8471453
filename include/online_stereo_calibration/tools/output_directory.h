/// @file output_directory.h
/// @brief Creating the output directory of an offline tool.
#pragma once

#include <string>

namespace osc {

/// Creates path and its missing parents (like mkdir -p).
/// @throws std::runtime_error naming the path if it is not a directory afterwards.
void makeDirectories(const std::string& path);

}  // namespace osc
