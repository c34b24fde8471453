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

/// Writes @p text to @p path atomically: a temporary file beside it (mode 0644), fsync, rename
/// over @p path, fsync of the directory. A reader sees the old file or the whole new one, also
/// after a crash or kill -9. @throws std::runtime_error naming the step and the errno text
/// ("... (old file, if any, kept)").
void writeTextFileAtomic(const std::string& path, const std::string& text);

}  // namespace osc
