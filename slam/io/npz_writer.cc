#include "slam/io/npz_writer.h"

#include <zlib.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace slamrig::slam {
namespace {

void Put16(std::string* s, std::uint32_t v) {
  s->push_back(static_cast<char>(v & 0xff));
  s->push_back(static_cast<char>((v >> 8) & 0xff));
}

void Put32(std::string* s, std::uint32_t v) {
  Put16(s, v & 0xffff);
  Put16(s, v >> 16);
}

template <typename T>
void PutRaw(std::string* s, T v) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &v, sizeof(T));  // little-endian hosts only, like the reader
  s->append(bytes, sizeof(T));
}

template <typename Int>
Int Integer(double v, const std::string& name) {
  const double r = std::round(v);
  if (!(r >= static_cast<double>(std::numeric_limits<Int>::min()) &&
        r <= static_cast<double>(std::numeric_limits<Int>::max()))) {
    throw std::invalid_argument("npz array '" + name + "': value " + std::to_string(v) +
                                " does not fit its integer dtype");
  }
  return static_cast<Int>(r);
}

// One .npy (format 1.0): magic, header padded so that the data starts at a multiple of 64.
std::string MakeNpy(const NpzArray& a) {
  std::size_t count = 1;
  std::string shape = "(";
  for (std::size_t s : a.shape) {
    count *= s;
    shape += std::to_string(s) + ",";
    if (a.shape.size() > 1) shape += " ";
  }
  if (a.shape.size() > 1) shape.resize(shape.size() - 2);
  shape += ")";
  if (count != a.values.size()) {
    throw std::invalid_argument("npz array '" + a.name + "': shape " + shape + " holds " +
                                std::to_string(count) + " values, got " +
                                std::to_string(a.values.size()));
  }
  std::string header =
      "{'descr': '" + a.dtype + "', 'fortran_order': False, 'shape': " + shape + ", }";
  const std::size_t unpadded = 10 + header.size() + 1;
  header.append((64 - unpadded % 64) % 64, ' ');
  header.push_back('\n');
  std::string npy = "\x93NUMPY";
  npy.push_back('\x01');
  npy.push_back('\x00');
  Put16(&npy, static_cast<std::uint32_t>(header.size()));
  npy += header;
  for (double v : a.values) {
    if (a.dtype == "<f8") {
      PutRaw(&npy, v);
    } else if (a.dtype == "<f4") {
      PutRaw(&npy, static_cast<float>(v));
    } else if (a.dtype == "<i4") {
      PutRaw(&npy, Integer<std::int32_t>(v, a.name));
    } else if (a.dtype == "<i2") {
      PutRaw(&npy, Integer<std::int16_t>(v, a.name));
    } else {
      throw std::invalid_argument("npz array '" + a.name + "': unsupported dtype '" + a.dtype +
                                  "'");
    }
  }
  return npy;
}

}  // namespace

std::string MakeNpz(const std::vector<NpzArray>& arrays) {
  constexpr std::uint32_t kDosDate = (0 << 9) | (1 << 5) | 1;  // 1980-01-01
  std::string zip, central;
  for (const NpzArray& array : arrays) {
    const std::string file = array.name + ".npy";
    const std::string data = MakeNpy(array);
    if (data.size() > 0xffffffffu || zip.size() > 0xffffffffu - data.size()) {
      throw std::invalid_argument("npz array '" + array.name + "': archive past 4 GiB (no zip64)");
    }
    const auto crc = static_cast<std::uint32_t>(
        crc32(0L, reinterpret_cast<const Bytef*>(data.data()), static_cast<uInt>(data.size())));
    const auto size = static_cast<std::uint32_t>(data.size());
    const auto offset = static_cast<std::uint32_t>(zip.size());
    Put32(&zip, 0x04034b50);
    Put16(&zip, 20);  // version needed
    Put16(&zip, 0);   // flags
    Put16(&zip, 0);   // stored
    Put16(&zip, 0);   // time
    Put16(&zip, kDosDate);
    Put32(&zip, crc);
    Put32(&zip, size);
    Put32(&zip, size);
    Put16(&zip, static_cast<std::uint32_t>(file.size()));
    Put16(&zip, 0);  // extra
    zip += file;
    zip += data;
    Put32(&central, 0x02014b50);
    Put16(&central, 20);  // made by
    Put16(&central, 20);  // needed
    Put16(&central, 0);
    Put16(&central, 0);
    Put16(&central, 0);
    Put16(&central, kDosDate);
    Put32(&central, crc);
    Put32(&central, size);
    Put32(&central, size);
    Put16(&central, static_cast<std::uint32_t>(file.size()));
    Put16(&central, 0);  // extra
    Put16(&central, 0);  // comment
    Put16(&central, 0);  // disk
    Put16(&central, 0);  // internal attributes
    Put32(&central, 0);  // external attributes
    Put32(&central, offset);
    central += file;
  }
  const auto central_offset = static_cast<std::uint32_t>(zip.size());
  zip += central;
  Put32(&zip, 0x06054b50);
  Put16(&zip, 0);
  Put16(&zip, 0);
  Put16(&zip, static_cast<std::uint32_t>(arrays.size()));
  Put16(&zip, static_cast<std::uint32_t>(arrays.size()));
  Put32(&zip, static_cast<std::uint32_t>(central.size()));
  Put32(&zip, central_offset);
  Put16(&zip, 0);
  return zip;
}

}  // namespace slamrig::slam
