#include "mesh/mve/mve.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/error.h"
#include "core/log.h"
#include "mesh/mve/case_table.h"
#include "mesh/mve/fill_component.h"

namespace naris::mve {

VolumeField::VolumeField(const Volume<float>& volume, InsideRule rule, double level)
    : volume_(volume),
      rule_(rule),
      level_(static_cast<float>(level)),
      to_index_(volume.frame.index_to_physical().inverse()) {}

namespace {

// A voxel's value as the field has it: positive inside. Labels become ±1, so that isopoints lie
// halfway between voxel centres, as for any binary mask.
template <InsideRule rule>
float field_value(float v, float level) {
  if constexpr (rule == InsideRule::above) return v - level;
  if constexpr (rule == InsideRule::below) return level - v;
  return v == level ? 1.0f : -1.0f;
}

// f(values) with the rule as a compile-time constant, so loops over voxels test it once.
template <class F>
void with_rule(InsideRule rule, float level, F&& f) {
  switch (rule) {
    case InsideRule::above:
      return f([level](float v) { return field_value<InsideRule::above>(v, level); });
    case InsideRule::below:
      return f([level](float v) { return field_value<InsideRule::below>(v, level); });
    case InsideRule::label:
      return f([level](float v) { return field_value<InsideRule::label>(v, level); });
  }
}

}  // namespace

float VolumeField::value(std::size_t voxel) const {
  float out = 0.0f;
  with_rule(rule_, level_, [&](auto value_of) { out = value_of(volume_.values[voxel]); });
  return out;
}

bool VolumeField::evaluate(const Eigen::Vector3d& x, double& value_at,
                           Eigen::Vector3d& gradient) const {
  const auto& dims = volume_.frame.dims;
  const Eigen::Vector3d c = to_index_ * (x - volume_.frame.origin);
  std::array<int, 3> lo;
  Eigen::Vector3d t;
  for (int a = 0; a < 3; ++a) {
    if (dims[a] < 2 || !(c[a] >= 0.0 && c[a] <= dims[a] - 1)) return false;
    lo[a] = std::min(static_cast<int>(c[a]), dims[a] - 2);
    t[a] = c[a] - lo[a];
  }
  double f[2][2][2];
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i)
        f[k][j][i] = value(volume_.frame.index(lo[0] + i, lo[1] + j, lo[2] + k));
  // Along i, then j, then k; the derivatives of each stage alongside.
  double fj[2][2], dfj_di[2][2];
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j) {
      fj[k][j] = f[k][j][0] + t[0] * (f[k][j][1] - f[k][j][0]);
      dfj_di[k][j] = f[k][j][1] - f[k][j][0];
    }
  double fk[2], dfk_di[2], dfk_dj[2];
  for (int k = 0; k < 2; ++k) {
    fk[k] = fj[k][0] + t[1] * (fj[k][1] - fj[k][0]);
    dfk_di[k] = dfj_di[k][0] + t[1] * (dfj_di[k][1] - dfj_di[k][0]);
    dfk_dj[k] = fj[k][1] - fj[k][0];
  }
  value_at = fk[0] + t[2] * (fk[1] - fk[0]);
  const Eigen::Vector3d d_index(dfk_di[0] + t[2] * (dfk_di[1] - dfk_di[0]),
                                dfk_dj[0] + t[2] * (dfk_dj[1] - dfk_dj[0]), fk[1] - fk[0]);
  gradient = to_index_.transpose() * d_index;
  return true;
}

void VolumeField::read_slice(int k, std::span<float> out) const {
  const auto in = volume_.slice(k);
  with_rule(rule_, level_, [&](auto value_of) {
    for (std::size_t n = 0; n < in.size(); ++n) out[n] = value_of(in[n]);
  });
}

namespace {

constexpr NodeId kNone = -1;

class Mesher {
 public:
  Mesher(const FieldSource& field, const MveOptions& options, HybridMesh& mesh, MveStats& stats)
      : field_(field), opt_(options), mesh_(mesh), stats_(stats) {
    const auto& dims = field.frame().dims;
    std::array<int, 3> n{};
    for (int a = 0; a < 3; ++a) {
      lo_[a] = std::max(0, options.crop.lo[a]);
      const int hi =
          options.crop.hi[a] < 0 ? dims[a] - 1 : std::min(options.crop.hi[a], dims[a] - 1);
      if (hi - lo_[a] < 1)
        fail("the crop box keeps fewer than two voxels along axis {} ({}..{})", a, lo_[a], hi);
      n[a] = hi - lo_[a] + 1;
    }
    nx_ = n[0];
    ny_ = n[1];
    nz_ = n[2];
    const std::size_t plane = static_cast<std::size_t>(nx_) * ny_;
    for (int s = 0; s < 2; ++s) {
      value_[s].resize(plane);
      vertex_[s].assign(plane, kNone);
      xedge_[s].assign(plane, kNone);
      yedge_[s].assign(plane, kNone);
      zface_[s].assign(plane, kNone);
    }
    zedge_.assign(plane, kNone);
    xface_.assign(plane, kNone);
    yface_.assign(plane, kNone);
    raw_.resize(static_cast<std::size_t>(dims[0]) * dims[1]);
    wall_ = mesh_.add_patch(opt_.wall_patch);
    binary_ = field.binary() && opt_.clip_planes.empty();
    track_components_ = opt_.keep_largest_component;
    for (int s = 0; s < 6; ++s) side_[s] = -1;
  }

  void run() {
    Progress progress("mve", static_cast<std::size_t>(nz_ - 1));
    load_slice(0, 1);
    for (int k = 0; k + 1 < nz_; ++k) {
      // Slice k+1 of the previous layer becomes slice 0 of this one.
      std::swap(value_[0], value_[1]);
      std::swap(object_[0], object_[1]);
      std::swap(row_inside_[0], row_inside_[1]);
      std::swap(vertex_[0], vertex_[1]);
      std::swap(xedge_[0], xedge_[1]);
      std::swap(yedge_[0], yedge_[1]);
      std::swap(zface_[0], zface_[1]);
      std::fill(vertex_[1].begin(), vertex_[1].end(), kNone);
      std::fill(xedge_[1].begin(), xedge_[1].end(), kNone);
      std::fill(yedge_[1].begin(), yedge_[1].end(), kNone);
      std::fill(zface_[1].begin(), zface_[1].end(), kNone);
      std::fill(zedge_.begin(), zedge_.end(), kNone);
      std::fill(xface_.begin(), xface_.end(), kNone);
      std::fill(yface_.begin(), yface_.end(), kNone);
      k_ = k;
      load_slice(k + 1, 1);
      for (int j = 0; j + 1 < ny_; ++j) {
        // Rows of cubes with no inside vertex make nothing.
        if (!row_inside_[0][j] && !row_inside_[0][j + 1] && !row_inside_[1][j] &&
            !row_inside_[1][j + 1])
          continue;
        for (int i = 0; i + 1 < nx_; ++i) mesh_cube(i, j);
      }
      progress.update(static_cast<std::size_t>(k + 1));
    }
  }

 private:
  void load_slice(int k, int s) {
    field_.read_slice(lo_[2] + k, raw_);
    const int nxf = field_.frame().dims[0];
    for (int j = 0; j < ny_; ++j) {
      const float* src = raw_.data() + static_cast<std::size_t>(lo_[1] + j) * nxf + lo_[0];
      std::copy(src, src + nx_, value_[s].begin() + static_cast<std::ptrdiff_t>(j) * nx_);
    }
    if (!opt_.clip_planes.empty()) apply_clip_planes(k, s);
    row_inside_[s].assign(static_cast<std::size_t>(ny_), 0);
    for (int j = 0; j < ny_; ++j) {
      const float* row = value_[s].data() + static_cast<std::size_t>(j) * nx_;
      row_inside_[s][j] = std::any_of(row, row + nx_, [](float v) { return v > 0.0f; });
    }
  }

  void apply_clip_planes(int k, int s) {
    // Inside means inside the object and on the kept side of every plane: the value is the
    // minimum; the object's own value is kept for placing isopoints.
    object_[s] = value_[s];
    for (int j = 0; j < ny_; ++j)
      for (int i = 0; i < nx_; ++i) {
        float& v = value_[s][static_cast<std::size_t>(j) * nx_ + i];
        const Eigen::Vector3d g(lo_[0] + i, lo_[1] + j, lo_[2] + k);
        for (const auto& plane : opt_.clip_planes) v = std::min(v, static_cast<float>(plane(g)));
      }
  }

  // Edge parameter of the isopoint, measured from vertex a.
  double crossing(int ia, int ja, int za, int ib, int jb, int zb) const {
    const double fa = value(ia, ja, za), fb = value(ib, jb, zb);
    if (opt_.clip_planes.empty()) return fa / (fa - fb);
    // From the inside end, the first zero of min(object, planes) along the edge.
    const bool a_inside = fa > 0.0;
    const int zi = a_inside ? za : zb, zo = a_inside ? zb : za;
    const int ii = a_inside ? ia : ib, io = a_inside ? ib : ia;
    const int ji = a_inside ? ja : jb, jo = a_inside ? jb : ja;
    auto object = [&](int i, int j, int z) {
      return double(object_[z][static_cast<std::size_t>(i) + static_cast<std::size_t>(nx_) * j]);
    };
    double t = 1.0;
    const double oi = object(ii, ji, zi), oo = object(io, jo, zo);
    if (oo <= 0.0) t = std::min(t, oi / (oi - oo));
    const Eigen::Vector3d gi(lo_[0] + ii, lo_[1] + ji, lo_[2] + k_ + zi);
    const Eigen::Vector3d go(lo_[0] + io, lo_[1] + jo, lo_[2] + k_ + zo);
    for (const auto& plane : opt_.clip_planes) {
      const double pi = plane(gi), po = plane(go);
      if (po <= 0.0) t = std::min(t, pi / (pi - po));
    }
    return a_inside ? t : 1.0 - t;
  }

  float value(int i, int j, int dz) const {
    return value_[dz][static_cast<std::size_t>(i) + static_cast<std::size_t>(nx_) * j];
  }

  NodeId add_node(const Eigen::Vector3d& x) {
    mesh_.nodes.push_back(x);
    const auto id = static_cast<NodeId>(mesh_.nodes.size() - 1);
    if (track_components_) parent_.push_back(id);
    return id;
  }

  // Connected components by union-find over nodes, built while cells are made (the nodes of a
  // new cell were made recently, so this pass stays in cache).
  NodeId find(NodeId a) {
    while (parent_[a] != a) a = parent_[a] = parent_[parent_[a]];
    return a;
  }
  template <class Cell>
  void unite(const Cell& c) {
    if (!track_components_) return;
    const NodeId r = find(c[0]);
    for (std::size_t k = 1; k < c.size(); ++k) {
      const NodeId q = find(c[k]);
      if (q != r) parent_[q] = r;
    }
  }

 public:
  BigVector<NodeId>& parents() { return parent_; }

 private:
  NodeId vertex_node(int i, int j, int dz) {
    NodeId& id = vertex_[dz][static_cast<std::size_t>(i) + static_cast<std::size_t>(nx_) * j];
    if (id == kNone) id = add_node(Eigen::Vector3d(i, j, k_ + dz));
    return id;
  }

  NodeId edge_node(int i, int j, int e) {
    const int a = kEdge[e][0], b = kEdge[e][1];
    const int gi = i + kCorner[a][0], gj = j + kCorner[a][1], dz = kCorner[a][2];
    NodeId* slot;
    switch (e / 4) {
      case 0:
        slot = &xedge_[dz][static_cast<std::size_t>(gi) + static_cast<std::size_t>(nx_) * gj];
        break;
      case 1:
        slot = &yedge_[dz][static_cast<std::size_t>(gi) + static_cast<std::size_t>(nx_) * gj];
        break;
      default:
        slot = &zedge_[static_cast<std::size_t>(gi) + static_cast<std::size_t>(nx_) * gj];
        break;
    }
    if (*slot == kNone) {
      double t = crossing(gi, gj, dz, i + kCorner[b][0], j + kCorner[b][1], kCorner[b][2]);
      t = std::clamp(t, opt_.isopoint_margin, 1.0 - opt_.isopoint_margin);
      Eigen::Vector3d x(gi, gj, k_ + dz);
      x[e / 4] += t;
      *slot = add_node(x);
    }
    return *slot;
  }

  NodeId face_node(int i, int j, int f, NodeId a, NodeId b) {
    NodeId* slot;
    const std::size_t row = static_cast<std::size_t>(nx_) * j;
    switch (f) {
      case 0:
        slot = &xface_[i + row];
        break;
      case 1:
        slot = &xface_[i + 1 + row];
        break;
      case 2:
        slot = &yface_[i + row];
        break;
      case 3:
        slot = &yface_[i + row + static_cast<std::size_t>(nx_)];
        break;
      case 4:
        slot = &zface_[0][i + row];
        break;
      default:
        slot = &zface_[1][i + row];
        break;
    }
    if (*slot == kNone) *slot = add_node(0.5 * (mesh_.nodes[a] + mesh_.nodes[b]));
    return *slot;
  }

  int side_patch(int side) {
    if (side_[side] < 0) side_[side] = mesh_.add_patch(opt_.side_patch[side]);
    return side_[side];
  }

  bool on_border(int i, int j, int f) const {
    switch (f) {
      case 0:
        return i == 0;
      case 1:
        return i + 2 == nx_;
      case 2:
        return j == 0;
      case 3:
        return j + 2 == ny_;
      case 4:
        return k_ == 0;
      default:
        return k_ + 2 == nz_;
    }
  }

  void add_border_faces(int i, int j, const CaseEntry& entry, const NodeId* ids) {
    for (int f = 0; f < 6; ++f) {
      if (!on_border(i, j, f)) continue;
      const int patch = side_patch(f);
      for (const auto& poly : entry.face_polygons[f]) {
        if (poly.size == 3) {
          mesh_.boundary_tris.push_back({ids[poly.p[0]], ids[poly.p[1]], ids[poly.p[2]]});
          mesh_.boundary_tri_patch.push_back(patch);
        } else {
          mesh_.boundary_quads.push_back(
              {ids[poly.p[0]], ids[poly.p[1]], ids[poly.p[2]], ids[poly.p[3]]});
          mesh_.boundary_quad_patch.push_back(patch);
        }
      }
    }
  }

  void mesh_cube(int i, int j) {
    float f[8];
    unsigned config = 0;
    for (int v = 0; v < 8; ++v) {
      f[v] = value(i + kCorner[v][0], j + kCorner[v][1], kCorner[v][2]);
      config |= static_cast<unsigned>(f[v] > 0.0f) << v;
    }
    if (config == 0) return;
    NodeId ids[kMaxLocalPoints];
    if (config == 255) {
      std::array<NodeId, 8> hex;
      for (int v = 0; v < 8; ++v)
        hex[v] = ids[v] = vertex_node(i + kCorner[v][0], j + kCorner[v][1], kCorner[v][2]);
      mesh_.hexes.push_back(hex);
      // Each of the hexahedron's 12 grid edges is owned by the cube whose vertex 0 is its lower
      // end; that cube is a hexahedron uniting its edges 0-1, 0-3, 0-4, or a boundary cube whose
      // cells contain every inside edge. So three unions suffice, except on the grid's upper
      // borders, where an owner cube may not exist.
      if (i + 2 < nx_ && j + 2 < ny_ && k_ + 2 < nz_) {
        unite(std::array<NodeId, 2>{hex[0], hex[1]});
        unite(std::array<NodeId, 2>{hex[0], hex[3]});
        unite(std::array<NodeId, 2>{hex[0], hex[4]});
      } else {
        unite(hex);
      }
      if (i == 0 || j == 0 || k_ == 0 || i + 2 == nx_ || j + 2 == ny_ || k_ + 2 == nz_)
        add_border_faces(i, j, case_entry(255, 0), ids);
      return;
    }

    for (int v = 0; v < 8; ++v) {
      if (!(config >> v & 1)) continue;
      ids[v] = vertex_node(i + kCorner[v][0], j + kCorner[v][1], kCorner[v][2]);
      x_[v] = mesh_.nodes[ids[v]];
    }
    const std::uint16_t crossed = crossing_edges(static_cast<std::uint8_t>(config));
    for (int e = 0; e < 12; ++e) {
      if (!(crossed >> e & 1)) continue;
      ids[kEdgePoint0 + e] = edge_node(i, j, e);
      x_[kEdgePoint0 + e] = mesh_.nodes[ids[kEdgePoint0 + e]];
    }

    // Each face's choice depends on that face alone, so both cubes sharing it agree.
    // Ambiguous faces: the bilinear saddle value decides (eq. 3.1–3.4). With the inside diagonal
    // (a, c) and the outside one (b, d), the saddle is inside iff a·c > b·d; ties separate.
    // Edge faces stay whole trapezoids where both isopoints (shared nodes) sit exactly at their
    // edges' midpoints, as everywhere on a labelmap but near its cut planes (case_table.h).
    const std::uint8_t amb = ambiguous_faces(static_cast<std::uint8_t>(config));
    const std::uint8_t edge = edge_faces(static_cast<std::uint8_t>(config));
    const Eigen::Vector3d corner0(i, j, k_);
    std::uint8_t choices = 0;
    for (int fc = 0; fc < 6; ++fc) {
      const auto& c = kFace[fc];
      if (edge >> fc & 1) {
        bool midpoints = true;
        for (int e : kFaceEdge[fc]) {
          if (!(crossed >> e & 1)) continue;
          const int axis = e / 4;
          midpoints = midpoints &&
                      x_[kEdgePoint0 + e][axis] - corner0[axis] - kCorner[kEdge[e][0]][axis] == 0.5;
        }
        if (midpoints) choices |= static_cast<std::uint8_t>(1u << fc);
        continue;
      }
      if (!(amb >> fc & 1)) continue;
      const bool first_inside = f[c[0]] > 0.0f;
      const double pin = first_inside ? double(f[c[0]]) * f[c[2]] : double(f[c[1]]) * f[c[3]];
      const double pout = first_inside ? double(f[c[1]]) * f[c[3]] : double(f[c[0]]) * f[c[2]];
      if (pin > pout) choices |= static_cast<std::uint8_t>(1u << fc);
    }
    const CaseEntry& entry = case_entry(static_cast<std::uint8_t>(config), choices);
    for (int fc = 0; fc < 6; ++fc) {
      if (!(entry.face_point_mask >> fc & 1)) continue;
      const auto& fe = entry.face_point_edges[fc];
      ids[kFacePoint0 + fc] =
          face_node(i, j, fc, ids[kEdgePoint0 + fe[0]], ids[kEdgePoint0 + fe[1]]);
      x_[kFacePoint0 + fc] = mesh_.nodes[ids[kFacePoint0 + fc]];
    }

    const Eigen::Vector3d cube_min(i, j, k_);
    for (const auto& comp : entry.components) {
      if (binary_)
        fill_component_binary(comp, cube_min, x_, fill_);
      else
        fill_component(comp, cube_min, x_, fill_);
      stats_.unresolved_cubes += !fill_.resolved;
      for (std::size_t n = 0; n < fill_.privates.size(); ++n)
        ids[kPrivatePoint0 + n] = add_node(fill_.privates[n]);
      for (const auto& t : fill_.tets) {
        mesh_.tets.push_back({ids[t[0]], ids[t[1]], ids[t[2]], ids[t[3]]});
        unite(mesh_.tets.back());
      }
      for (const auto& p : fill_.pyramids) {
        mesh_.pyramids.push_back({ids[p[0]], ids[p[1]], ids[p[2]], ids[p[3]], ids[p[4]]});
        unite(mesh_.pyramids.back());
      }
      for (const auto& t : fill_.iso_triangles) {
        mesh_.boundary_tris.push_back({ids[t[0]], ids[t[1]], ids[t[2]]});
        mesh_.boundary_tri_patch.push_back(wall_);
      }
    }
    add_border_faces(i, j, entry, ids);
  }

  const FieldSource& field_;
  const MveOptions& opt_;
  HybridMesh& mesh_;
  MveStats& stats_;
  std::array<int, 3> lo_{};
  int nx_ = 0, ny_ = 0, nz_ = 0, k_ = 0;
  std::vector<float> raw_;
  std::vector<float> value_[2];
  std::vector<float> object_[2];  // the object's own values, when clip planes are given
  std::vector<char> row_inside_[2];
  std::vector<NodeId> vertex_[2], xedge_[2], yedge_[2], zface_[2];
  std::vector<NodeId> zedge_, xface_, yface_;
  int wall_ = 0;
  int side_[6];
  std::array<Eigen::Vector3d, kMaxLocalPoints> x_;  // local point positions of the cube
  bool binary_ = false;
  bool track_components_ = false;
  BigVector<NodeId> parent_;
  ComponentFill fill_;
};

// Keeps the connected component (through shared nodes) with the most cells, given the
// union-find forest the mesher built.
void keep_largest_component(HybridMesh& mesh, BigVector<NodeId>& parent, MveStats& stats) {
  auto find = [&](NodeId a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  std::size_t roots = 0;
  for (std::size_t n = 0; n < parent.size(); ++n) roots += parent[n] == static_cast<NodeId>(n);
  stats.components = roots;
  if (roots <= 1) return;  // the common case: nothing to drop, no further pass
  std::vector<std::uint32_t> cells_of(mesh.nodes.size(), 0);
  auto count = [&](const auto& cells) {
    for (const auto& c : cells) ++cells_of[find(c[0])];
  };
  count(mesh.tets);
  count(mesh.pyramids);
  count(mesh.hexes);
  std::size_t components = 0;
  NodeId largest = 0;
  for (std::size_t n = 0; n < cells_of.size(); ++n) {
    if (!cells_of[n]) continue;
    ++components;
    if (cells_of[n] > cells_of[largest]) largest = static_cast<NodeId>(n);
  }
  stats.components = components;
  if (components <= 1) return;
  stats.dropped_components = components - 1;
  auto keep = [&](auto& cells) {
    const auto before = cells.size();
    cells.erase(std::remove_if(cells.begin(), cells.end(),
                               [&](const auto& c) { return find(c[0]) != largest; }),
                cells.end());
    stats.dropped_cells += before - cells.size();
  };
  keep(mesh.tets);
  keep(mesh.pyramids);
  keep(mesh.hexes);
  auto keep_faces = [&](auto& faces, auto& patches) {
    std::size_t out = 0;
    for (std::size_t n = 0; n < faces.size(); ++n) {
      if (find(faces[n][0]) != largest) continue;
      faces[out] = faces[n];
      patches[out++] = patches[n];
    }
    faces.resize(out);
    patches.resize(out);
  };
  keep_faces(mesh.boundary_tris, mesh.boundary_tri_patch);
  keep_faces(mesh.boundary_quads, mesh.boundary_quad_patch);
}

}  // namespace

HybridMesh march_volume_elements(const FieldSource& field, const MveOptions& options,
                                 MveStats* stats_out) {
  MveStats stats;
  HybridMesh mesh;
  Mesher mesher(field, options, mesh, stats);
  mesher.run();
  if (mesh.cell_count() == 0)
    fail("nothing is inside: no voxel passes the threshold or label in the meshed region");
  if (options.keep_largest_component) keep_largest_component(mesh, mesher.parents(), stats);
  // Nodes are made only when a cell needs them: unused ones exist only after dropping.
  if (stats.dropped_components) compact_nodes(mesh);
  remove_empty_patches(mesh);

  // Index space → physical millimetres. A mirroring frame turns every cell inside out, so the
  // node order is reversed to keep volumes positive.
  const ImageFrame& frame = field.frame();
  const Eigen::Matrix3d m = frame.index_to_physical();
  Eigen::Vector3d offset(options.crop.lo[0] > 0 ? options.crop.lo[0] : 0,
                         options.crop.lo[1] > 0 ? options.crop.lo[1] : 0,
                         options.crop.lo[2] > 0 ? options.crop.lo[2] : 0);
  for (auto& x : mesh.nodes) x = frame.origin + m * (x + offset);
  if (m.determinant() < 0.0) flip_orientation(mesh);
  if (stats_out) *stats_out = stats;
  return mesh;
}

}  // namespace naris::mve
