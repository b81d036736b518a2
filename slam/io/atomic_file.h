#pragma once

#include <string>

namespace slamrig::slam {

/// Writes `contents` to `path` through a temporary file in the same folder and a rename, so a
/// killed run never leaves a half-written file that looks complete. Throws std::runtime_error
/// naming the path when the folder is not writable.
void WriteFileAtomically(const std::string& path, const std::string& contents);

}  // namespace slamrig::slam
