#include "mesh/io/write_gmsh.h"

#include <fmt/format.h>

#include <charconv>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string_view>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"

namespace naris {

namespace {

// A file written through a large buffer that numbers are printed into directly (std::to_chars:
// shortest round-trip doubles), since a mesh file holds tens of millions of them.
class TextOut {
 public:
  TextOut(std::FILE* file, const std::filesystem::path& path) : file_(file), path_(path) {
    buffer_.resize(kSize + kSlack);
  }
  void text(std::string_view s) {
    if (s.size() > kSlack) {
      flush();
      put(s.data(), s.size());
      return;
    }
    std::memcpy(buffer_.data() + used_, s.data(), s.size());
    advance(s.size());
  }
  template <class Number>
  void number(Number x) {
    const auto [end, ec] = std::to_chars(buffer_.data() + used_, buffer_.data() + used_ + 64, x);
    advance(static_cast<std::size_t>(end - (buffer_.data() + used_)));
  }
  void character(char c) {
    buffer_[used_] = c;
    advance(1);
  }
  void flush() {
    put(buffer_.data(), used_);
    used_ = 0;
  }

 private:
  static constexpr std::size_t kSize = 1 << 20, kSlack = 256;
  void advance(std::size_t n) {
    used_ += n;
    if (used_ >= kSize) flush();
  }
  void put(const char* data, std::size_t n) {
    if (std::fwrite(data, 1, n, file_) != n) fail("{}: write failed (disk full?)", path_.string());
  }
  std::FILE* file_;
  const std::filesystem::path& path_;
  std::vector<char> buffer_;
  std::size_t used_ = 0;
};

}  // namespace

void write_gmsh22(const HybridMesh& mesh, const std::filesystem::path& path) {
  AtomicOutput out(path);
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(out.temp_path().c_str(), "w"),
                                                       &std::fclose);
  if (!file) fail("{}: cannot open for writing", path.string());
  TextOut o(file.get(), path);
  const int fluid = static_cast<int>(mesh.patch_names.size()) + 1;
  o.text(fmt::format("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n{}\n",
                     mesh.patch_names.size() + 1));
  for (std::size_t p = 0; p < mesh.patch_names.size(); ++p)
    o.text(fmt::format("2 {} \"{}\"\n", p + 1, mesh.patch_names[p]));
  o.text(fmt::format("3 {} \"fluid\"\n$EndPhysicalNames\n$Nodes\n{}\n", fluid, mesh.nodes.size()));
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
    o.number(n + 1);
    for (double x : mesh.nodes[n]) {
      o.character(' ');
      o.number(x);
    }
    o.character('\n');
  }
  const std::size_t elements =
      mesh.boundary_tris.size() + mesh.boundary_quads.size() + mesh.cell_count();
  o.text(fmt::format("$EndNodes\n$Elements\n{}\n", elements));
  std::size_t id = 0;
  auto element = [&](int type, int physical, const auto& nodes) {
    o.number(++id);
    for (int v : {type, 2, physical, physical}) {
      o.character(' ');
      o.number(v);
    }
    for (NodeId v : nodes) {
      o.character(' ');
      o.number(v + 1);
    }
    o.character('\n');
  };
  for (std::size_t f = 0; f < mesh.boundary_tris.size(); ++f)
    element(2, mesh.boundary_tri_patch[f] + 1, mesh.boundary_tris[f]);
  for (std::size_t f = 0; f < mesh.boundary_quads.size(); ++f)
    element(3, mesh.boundary_quad_patch[f] + 1, mesh.boundary_quads[f]);
  for (const auto& c : mesh.tets) element(4, fluid, c);
  for (const auto& c : mesh.pyramids) element(7, fluid, c);
  for (const auto& c : mesh.hexes) element(5, fluid, c);
  o.text("$EndElements\n");
  o.flush();
  if (std::fflush(file.get()) != 0) fail("{}: write failed (disk full?)", path.string());
  file.reset();
  out.commit();
}

}  // namespace naris
