// numpy .npz reading: the NPY format (numpy/lib/format.py, "NPY format version 1.0-3.0": magic,
// header length, Python-literal dict with descr, fortran_order and shape) inside a PKZIP archive
// (APPNOTE.TXT 6.3: end of central directory, central directory headers, local file headers,
// zip64 extended information extra field 0x0001).
#include "slam/io/npz_reader.h"

#include <zlib.h>

#include <charconv>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>

#include "slam/types/error.h"

namespace slamrig::slam {
namespace {

std::uint64_t Le(const std::string& b, std::size_t at, int bytes, const std::string& where) {
  if (at > b.size() || b.size() - at < static_cast<std::size_t>(bytes)) {
    throw ParseError(where + ": truncated");
  }
  std::uint64_t v = 0;
  for (int i = bytes - 1; i >= 0; --i)
    v = (v << 8) | static_cast<unsigned char>(b[at + static_cast<std::size_t>(i)]);
  return v;
}

// Deflate expands at most 1032:1 (RFC 1951 blocks of 258-byte matches): a larger declared size
// is a corrupt header, refused before allocating it.
constexpr std::uint64_t kMaxDeflateRatio = 1032;

std::string Inflate(const std::string& compressed, std::uint64_t size, const std::string& where) {
  if (size > (compressed.size() + 1) * kMaxDeflateRatio) {
    throw ParseError(where + ": uncompressed size " + std::to_string(size) + " is impossible for " +
                     std::to_string(compressed.size()) + " deflated bytes");
  }
  std::string out(static_cast<std::size_t>(size), '\0');
  z_stream z{};
  if (inflateInit2(&z, -MAX_WBITS) != Z_OK) throw ParseError(where + ": zlib init failed");
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(compressed.data()));
  z.avail_in = static_cast<uInt>(compressed.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  const int status = inflate(&z, Z_FINISH);
  const std::size_t produced = z.total_out;
  inflateEnd(&z);
  if (status != Z_STREAM_END || produced != size)
    throw ParseError(where + ": corrupt deflate data");
  return out;
}

// Value of 'key' in the header dict, as the raw literal text up to the next top-level comma.
std::string DictValue(const std::string& header, const std::string& key, const std::string& name) {
  const std::size_t k = header.find("'" + key + "'");
  if (k == std::string::npos) throw ParseError(name + ": npy header has no '" + key + "'");
  std::size_t v = header.find(':', k);
  if (v == std::string::npos) throw ParseError(name + ": npy header: no value for '" + key + "'");
  ++v;
  while (v < header.size() && header[v] == ' ') ++v;
  int depth = 0;
  std::size_t end = v;
  for (; end < header.size(); ++end) {
    const char c = header[end];
    if (c == '(') ++depth;
    if (c == ')') --depth;
    if ((c == ',' || c == '}') && depth == 0) break;
  }
  return header.substr(v, end - v);
}

template <typename T>
void Convert(const char* data, std::size_t n, std::vector<double>* out) {
  out->resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    T v;
    std::memcpy(&v, data + i * sizeof(T), sizeof(T));
    (*out)[i] = static_cast<double>(v);
  }
}

}  // namespace

NpyArray ParseNpy(const std::string& bytes, const std::string& name) {
  if (bytes.size() < 10 || bytes.compare(0, 6, "\x93NUMPY") != 0) {
    throw ParseError(name + ": not a .npy array (bad magic)");
  }
  const int major = static_cast<unsigned char>(bytes[6]);
  const std::size_t header_len = static_cast<std::size_t>(Le(bytes, 8, major == 1 ? 2 : 4, name));
  const std::size_t header_at = major == 1 ? 10 : 12;
  if (header_at + header_len > bytes.size()) throw ParseError(name + ": truncated npy header");
  const std::string header = bytes.substr(header_at, header_len);

  NpyArray array;
  std::string descr = DictValue(header, "descr", name);
  if (descr.size() < 2 || descr.front() != '\'' || descr.back() != '\'') {
    throw ParseError(name + ": npy descr " + descr + " is not a simple dtype");
  }
  array.dtype = descr.substr(1, descr.size() - 2);
  const bool fortran = DictValue(header, "fortran_order", name) == "True";
  const std::string shape_text = DictValue(header, "shape", name);
  std::size_t count = 1;
  {
    std::string digits;
    for (const char c : shape_text + ",") {
      if (c >= '0' && c <= '9') {
        digits += c;
      } else if (!digits.empty()) {
        std::size_t dim = 0;
        const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), dim);
        // Element counts past 2^48 cannot be in a file anyway; refusing them keeps count * item
        // below 2^64.
        if (ec != std::errc() || (dim != 0 && count > (std::size_t{1} << 48) / dim)) {
          throw ParseError(name + ": npy shape " + shape_text + " is too large");
        }
        array.shape.push_back(dim);
        count *= dim;
        digits.clear();
      }
    }
  }
  const std::string& t = array.dtype;
  const bool big_endian = !t.empty() && t[0] == '>';
  const std::string kind =
      t.size() > 1 && (t[0] == '<' || t[0] == '|' || t[0] == '=') ? t.substr(1) : t;
  if (big_endian) throw ParseError(name + ": big-endian dtype " + t + " is not supported");
  std::size_t item = 0;
  const char* data = bytes.data() + header_at + header_len;
  const std::size_t available = bytes.size() - header_at - header_len;
  auto need = [&](std::size_t size) {
    item = size;
    if (count * item > available) throw ParseError(name + ": array data truncated");
  };
  std::vector<double> flat;
  if (kind == "f8") {
    need(8);
    Convert<double>(data, count, &flat);
  } else if (kind == "f4") {
    need(4);
    Convert<float>(data, count, &flat);
  } else if (kind == "i1") {
    need(1);
    Convert<std::int8_t>(data, count, &flat);
  } else if (kind == "i2") {
    need(2);
    Convert<std::int16_t>(data, count, &flat);
  } else if (kind == "i4") {
    need(4);
    Convert<std::int32_t>(data, count, &flat);
  } else if (kind == "i8") {
    need(8);
    Convert<std::int64_t>(data, count, &flat);
  } else if (kind == "u1" || kind == "b1") {
    need(1);
    Convert<std::uint8_t>(data, count, &flat);
  } else if (kind == "u2") {
    need(2);
    Convert<std::uint16_t>(data, count, &flat);
  } else if (kind == "u4") {
    need(4);
    Convert<std::uint32_t>(data, count, &flat);
  } else if (kind == "u8") {
    need(8);
    Convert<std::uint64_t>(data, count, &flat);
  } else
    throw ParseError(name + ": dtype " + t + " is not supported");

  if (!fortran || array.shape.size() < 2) {
    array.values = std::move(flat);
    return array;
  }
  // Fortran order: the first index varies fastest. Reorder to C order (2-D and up).
  array.values.resize(count);
  const std::size_t dims = array.shape.size();
  std::vector<std::size_t> index(dims, 0);
  for (std::size_t f = 0; f < count; ++f) {
    std::size_t c = 0;
    for (std::size_t d = 0; d < dims; ++d) c = c * array.shape[d] + index[d];
    array.values[c] = flat[f];
    for (std::size_t d = 0; d < dims; ++d) {
      if (++index[d] < array.shape[d]) break;
      index[d] = 0;
    }
  }
  return array;
}

std::map<std::string, NpyArray> ReadNpz(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw ParseError(path + ": no such file");
  const std::string b((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  // End of central directory: the last "PK\5\6" within the final 64 KiB + 22 bytes.
  std::size_t eocd = std::string::npos;
  for (std::size_t i = b.size() >= 22 ? b.size() - 22 : 0;; --i) {
    if (b.compare(i, 4, "PK\x05\x06") == 0) {
      eocd = i;
      break;
    }
    if (i == 0 || b.size() - i > 65557) break;
  }
  if (eocd == std::string::npos) throw ParseError(path + ": not a zip (.npz) archive");
  const std::size_t entries = static_cast<std::size_t>(Le(b, eocd + 10, 2, path));
  std::size_t at = static_cast<std::size_t>(Le(b, eocd + 16, 4, path));

  std::map<std::string, NpyArray> arrays;
  for (std::size_t e = 0; e < entries; ++e) {
    if (Le(b, at, 4, path) != 0x02014b50)
      throw ParseError(path + ": corrupt zip central directory");
    const int method = static_cast<int>(Le(b, at + 10, 2, path));
    std::uint64_t compressed = Le(b, at + 20, 4, path);
    std::uint64_t size = Le(b, at + 24, 4, path);
    const std::size_t name_len = static_cast<std::size_t>(Le(b, at + 28, 2, path));
    const std::size_t extra_len = static_cast<std::size_t>(Le(b, at + 30, 2, path));
    const std::size_t comment_len = static_cast<std::size_t>(Le(b, at + 32, 2, path));
    std::uint64_t local = Le(b, at + 42, 4, path);
    const std::string name = b.substr(at + 46, name_len);
    // Zip64: the 0xFFFFFFFF fields come, in order, from extra field 0x0001.
    std::size_t x = at + 46 + name_len;
    const std::size_t x_end = x + extra_len;
    while (x + 4 <= x_end) {
      const auto id = Le(b, x, 2, path);
      const auto len = static_cast<std::size_t>(Le(b, x + 2, 2, path));
      if (id == 0x0001) {
        std::size_t f = x + 4;
        if (size == 0xFFFFFFFFu) {
          size = Le(b, f, 8, path);
          f += 8;
        }
        if (compressed == 0xFFFFFFFFu) {
          compressed = Le(b, f, 8, path);
          f += 8;
        }
        if (local == 0xFFFFFFFFu) {
          local = Le(b, f, 8, path);
        }
      }
      x += 4 + len;
    }
    at = x_end + comment_len;

    const std::string where = path + ": " + name;
    const auto lo = static_cast<std::size_t>(local);
    if (Le(b, lo, 4, where) != 0x04034b50) throw ParseError(where + ": corrupt local header");
    const std::size_t data_at = lo + 30 + static_cast<std::size_t>(Le(b, lo + 26, 2, where)) +
                                static_cast<std::size_t>(Le(b, lo + 28, 2, where));
    if (data_at > b.size() || compressed > b.size() - data_at) {
      throw ParseError(where + ": truncated");
    }
    const std::string raw = b.substr(data_at, static_cast<std::size_t>(compressed));
    std::string bytes;
    if (method == 0) {
      bytes = raw;
    } else if (method == 8) {
      bytes = Inflate(raw, size, where);
    } else {
      throw ParseError(where + ": zip compression method " + std::to_string(method) +
                       " not supported");
    }
    std::string key = name;
    if (key.size() > 4 && key.compare(key.size() - 4, 4, ".npy") == 0) key.resize(key.size() - 4);
    arrays[key] = ParseNpy(bytes, where);
  }
  return arrays;
}

}  // namespace slamrig::slam
