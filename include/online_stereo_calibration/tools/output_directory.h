/// @file output_directory.h
/// @brief Files and directories of the offline tools: creating an output directory, the
/// directory part of a path, whether a regular file exists.
#pragma once

#include <string>

namespace osc {

/// Creates path and its missing parents (like mkdir -p).
/// @throws std::runtime_error naming the path if it is not a directory afterwards.
void makeDirectories(const std::string& path);

/// The directory part of @p path: "." without a slash, "/" for a file in the root.
std::string directoryOf(const std::string& path);

/// True if @p path names an existing regular file (after following links).
bool isRegularFile(const std::string& path);

}  // namespace osc
