#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace slamrig::slam {

/// One array to write into a numpy .npz archive.
struct NpzArray {
  std::string name;                ///< key in the archive (stored as name + ".npy")
  std::string dtype = "<f8";       ///< "<f8", "<f4", "<i4" or "<i2"
  std::vector<std::size_t> shape;  ///< () for a scalar
  std::vector<double> values;      ///< C (row-major) order; converted to dtype (integers rounded)
};

/// The bytes of a numpy .npz archive (a stored zip of .npy format 1.0 files, dated 1980-01-01 so
/// that equal arrays give equal bytes) holding `arrays`, which numpy.load and ReadNpz read. Throws
/// std::invalid_argument for an unknown dtype, a shape that does not match the values, or a value
/// out of an integer dtype's range.
std::string MakeNpz(const std::vector<NpzArray>& arrays);

}  // namespace slamrig::slam
