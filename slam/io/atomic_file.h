#pragma once

#include <string>

namespace slamrig::slam {

/// Writes `contents` to `path` through a temporary file in the same folder and a rename, so a
/// killed run never leaves a half-written file that looks complete. Throws OutputError naming
/// the path when it cannot be written (a full disk, a read-only folder; the temporary file is
/// removed), Interrupted when SIGINT/SIGTERM arrived before it (nothing is written).
void WriteFileAtomically(const std::string& path, const std::string& contents);

/// Checks, without creating anything, that `dir` could be written: it, or the nearest folder
/// above it that exists, is a writable folder (access(2), which sees a read-only mount even as
/// root). A command checks its output folder before its work, so that a read-only one fails
/// at once rather than after minutes of simulation. Throws OutputError naming the folder.
void CheckOutputFolder(const std::string& dir);

}  // namespace slamrig::slam
