#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace slamrig::slam {

/// One array of a numpy .npy/.npz file, converted to double, in C (row-major) order.
struct NpyArray {
  std::string dtype;               ///< numpy descr, e.g. "<f8", "<i2"
  std::vector<std::size_t> shape;  ///< () for a scalar
  std::vector<double> values;      ///< row-major: element (i, j) of a 2-D array at i * shape[1] + j

  /// Number of elements (1 for a scalar).
  std::size_t size() const { return values.size(); }
};

/// Reads every array of a numpy .npz archive (zip, stored or deflated, zip64 sizes accepted),
/// keyed by name without ".npy". Supported dtypes: little-endian f4, f8, i1, i2, i4, i8, u1, u2,
/// u4, u8 and bool. Throws ParseError naming the file (and the array) when the archive or an
/// array header is broken or a dtype is not supported.
std::map<std::string, NpyArray> ReadNpz(const std::string& path);

/// Parses the bytes of one .npy file; `name` is used in error messages.
NpyArray ParseNpy(const std::string& bytes, const std::string& name);

}  // namespace slamrig::slam
