#pragma once

#include <string>

namespace slamrig::app {

/// The datasets folder: $SLAMRIG_DATA_DIR, else ../shared/datasets.
std::string DataDir();

/// `path` itself when it exists, else `path` inside DataDir() when that exists (so users can
/// type `carmen_corrected/intel-corrected.log.gz`), else `path` unchanged (the reader then
/// reports it missing).
std::string ResolveDataPath(const std::string& path);

}  // namespace slamrig::app
