#include "mesh/image/write_volume.h"

#include <fmt/format.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string_view>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"

namespace naris {
namespace {

void write_nrrd(const ImageFrame& f, std::string_view type, const void* data, std::size_t bytes,
                const std::filesystem::path& path) {
  const Eigen::Matrix3d m = f.index_to_physical();
  auto vec = [](const Eigen::Vector3d& v) {
    return fmt::format("({:.17g},{:.17g},{:.17g})", v[0], v[1], v[2]);
  };
  const std::string header = fmt::format(
      "NRRD0004\n# written by naris\ntype: {}\ndimension: 3\nspace: left-posterior-superior\n"
      "sizes: {} {} {}\nspace directions: {} {} {}\nkinds: domain domain domain\nendian: "
      "little\nencoding: gzip\nspace origin: {}\n\n",
      type, f.dims[0], f.dims[1], f.dims[2], vec(m.col(0)), vec(m.col(1)), vec(m.col(2)),
      vec(f.origin));
  // zlib counts in 32 bits: deflate in chunks so volumes beyond 4 GiB compress too.
  std::string packed;
  z_stream z{};
  if (deflateInit2(&z, 1, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY) != Z_OK)
    fail("{}: cannot start compression", path.string());
  const auto* in = static_cast<const Bytef*>(data);
  std::size_t left = bytes;
  std::vector<char> chunk(1 << 20);
  int rc = Z_OK;
  do {
    const std::size_t take = std::min<std::size_t>(left, 1u << 30);
    z.next_in = const_cast<Bytef*>(in);
    z.avail_in = static_cast<uInt>(take);
    in += take;
    left -= take;
    const int flush = left == 0 ? Z_FINISH : Z_NO_FLUSH;
    do {
      z.next_out = reinterpret_cast<Bytef*>(chunk.data());
      z.avail_out = static_cast<uInt>(chunk.size());
      rc = deflate(&z, flush);
      packed.append(chunk.data(), chunk.size() - z.avail_out);
    } while (z.avail_out == 0);
  } while (left > 0);
  deflateEnd(&z);
  if (rc != Z_STREAM_END) fail("{}: compression failed", path.string());
  AtomicOutput out(path);
  {
    std::ofstream file(out.temp_path(), std::ios::binary);
    file << header << packed;
    if (!file) fail("{}: write failed (disk full?)", path.string());
  }
  out.commit();
}

}  // namespace

void write_labelmap_nrrd(const Volume<std::uint8_t>& mask, const std::filesystem::path& path) {
  write_nrrd(mask.frame, "uint8", mask.values.data(), mask.values.size(), path);
}

void write_ct_nrrd(const Volume<float>& ct, const std::filesystem::path& path) {
  std::vector<std::int16_t> hu(ct.values.size());
  std::transform(ct.values.begin(), ct.values.end(), hu.begin(), [](float v) {
    return static_cast<std::int16_t>(std::clamp(std::lround(v), -32768l, 32767l));
  });
  write_nrrd(ct.frame, "int16", hu.data(), hu.size() * sizeof(std::int16_t), path);
}

void write_field_nrrd(const Volume<float>& field, const std::filesystem::path& path) {
  write_nrrd(field.frame, "float", field.values.data(), field.values.size() * sizeof(float), path);
}

}  // namespace naris
