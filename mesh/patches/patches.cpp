#include "mesh/patches/patches.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <regex>

#include "core/error.h"
#include "core/text.h"

namespace naris {
namespace {

std::vector<double> parse_numbers(const std::string& text, const std::string& context) {
  std::vector<double> out;
  for (const std::string& item : split_list(text)) {
    try {
      std::size_t used = 0;
      out.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      fail("'{}': '{}' is not a number", context, item);
    }
    if (!std::isfinite(out.back())) fail("'{}': '{}' is not a finite number", context, item);
  }
  return out;
}

Eigen::Vector3d inside_centroid(const mve::FieldSource& field) {
  const auto& d = field.frame().dims;
  std::vector<float> slice(static_cast<std::size_t>(d[0]) * d[1]);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double count = 0.0;
  for (int k = 0; k < d[2]; ++k) {
    field.read_slice(k, slice);
    for (int j = 0; j < d[1]; ++j)
      for (int i = 0; i < d[0]; ++i)
        if (slice[static_cast<std::size_t>(j) * d[0] + i] > 0.0f) {
          sum += Eigen::Vector3d(i, j, k);
          count += 1.0;
        }
  }
  if (count == 0.0) fail("nothing is inside: no voxel passes the threshold or label");
  return sum / count;
}

}  // namespace

CutPlane parse_cut_plane(const std::string& text) {
  CutPlane plane;
  plane.text = text;
  static const std::regex index_form(R"(^\s*([ijk])\s*=\s*([-+0-9.eE]+)\s*$)");
  static const std::regex physical_form(R"(^\s*p\s*=\s*([^;]+);\s*n\s*=\s*(.+)$)");
  std::smatch m;
  if (std::regex_match(text, m, index_form)) {
    plane.index_plane = true;
    plane.axis = m[1].str()[0] - 'i';
    plane.index = parse_numbers(m[2].str(), text)[0];
    return plane;
  }
  if (std::regex_match(text, m, physical_form)) {
    const auto p = parse_numbers(m[1].str(), text), n = parse_numbers(m[2].str(), text);
    if (p.size() != 3 || n.size() != 3)
      fail("plane '{}': p and n need three numbers each (p=x,y,z;n=nx,ny,nz)", text);
    plane.point = Eigen::Vector3d(p[0], p[1], p[2]);
    plane.normal = Eigen::Vector3d(n[0], n[1], n[2]);
    if (!(plane.normal.norm() > 0.0)) fail("plane '{}': the normal is zero", text);
    plane.normal.normalize();
    return plane;
  }
  fail(
      "plane '{}' not understood: give a voxel-index plane such as j=20, or a physical one such "
      "as p=0,12.5,0;n=0,1,0 (millimetres)",
      text);
}

bool Region::contains(const Eigen::Vector3d& x) const {
  if (sphere) return (x - a).norm() <= radius;
  return (x.array() >= a.array()).all() && (x.array() <= b.array()).all();
}

Region parse_region(const std::string& text) {
  static const std::regex form(R"(^\s*([A-Za-z_][A-Za-z0-9_-]*)\s*:\s*(box|sphere)\s*=\s*(.+)$)");
  std::smatch m;
  if (!std::regex_match(text, m, form))
    fail(
        "region '{}' not understood: give name:box=x0,y0,z0,x1,y1,z1 or name:sphere=x,y,z,r "
        "(millimetres)",
        text);
  Region r;
  r.name = m[1].str();
  const auto v = parse_numbers(m[3].str(), text);
  if (m[2].str() == "box") {
    if (v.size() != 6) fail("region '{}': a box needs six numbers", text);
    r.a = Eigen::Vector3d(std::min(v[0], v[3]), std::min(v[1], v[4]), std::min(v[2], v[5]));
    r.b = Eigen::Vector3d(std::max(v[0], v[3]), std::max(v[1], v[4]), std::max(v[2], v[5]));
  } else {
    if (v.size() != 4 || !(v[3] > 0.0))
      fail("region '{}': a sphere needs x,y,z,r with r > 0", text);
    r.sphere = true;
    r.a = Eigen::Vector3d(v[0], v[1], v[2]);
    r.radius = v[3];
  }
  return r;
}

PreparedCuts prepare_cuts(const mve::FieldSource& field, const std::vector<Cut>& cuts,
                          mve::MveOptions& options) {
  PreparedCuts prepared;
  if (cuts.empty()) return prepared;
  const ImageFrame& frame = field.frame();
  prepared.centroid_index = inside_centroid(field);
  // Each cut keeps the side that holds the other cuts' points (an inlet and an outlet keep what
  // lies between them), or the object's centroid when it is alone. An index plane's point is the
  // centroid moved onto it.
  const bool between = cuts.size() > 1;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> points;
  for (const Cut& c : cuts) {
    Eigen::Vector3d x = prepared.centroid_index;
    if (c.plane.index_plane)
      x[c.plane.axis] = c.plane.index;
    else
      x = frame.continuous_index(c.plane.point);
    points.push_back(x);
    sum += x;
  }
  for (std::size_t i = 0; i < cuts.size(); ++i) {
    const Cut& cut = cuts[i];
    const Eigen::Vector3d keep =
        between ? Eigen::Vector3d((sum - points[i]) / static_cast<double>(cuts.size() - 1))
                : prepared.centroid_index;
    int axis = -1;
    double index = 0.0;
    if (cut.plane.index_plane) {
      axis = cut.plane.axis;
      index = cut.plane.index;
    } else {
      // A physical plane along an image axis (within half a degree) is a voxel-index plane.
      for (int a = 0; a < 3; ++a)
        if (std::abs(frame.direction.col(a).dot(cut.plane.normal)) > std::cos(0.5 * M_PI / 180.0))
          axis = a;
      if (axis >= 0) index = frame.continuous_index(cut.plane.point)[axis];
    }
    if (axis >= 0) {
      const int at = static_cast<int>(std::lround(index));
      if (at < 0 || at >= frame.dims[axis])
        fail("{} plane '{}' lies outside the image (index {} of 0..{})", cut.patch, cut.plane.text,
             at, frame.dims[axis] - 1);
      if (between && std::abs(keep[axis] - index) < 0.5)
        fail(
            "the {} plane '{}' lies in the voxel plane of the other cuts: nothing is between "
            "them",
            cut.patch, cut.plane.text);
      if (keep[axis] >= at) {
        options.crop.lo[axis] = std::max(options.crop.lo[axis], at);
        options.side_patch[2 * axis] = cut.patch;
      } else {
        options.crop.hi[axis] =
            options.crop.hi[axis] < 0 ? at : std::min(options.crop.hi[axis], at);
        options.side_patch[2 * axis + 1] = cut.patch;
      }
      continue;
    }
    const Eigen::Vector3d c = frame.physical(keep);
    Eigen::Vector3d n = cut.plane.normal;
    const double side = n.dot(c - cut.plane.point);
    if (between && std::abs(side) < 0.5 * frame.spacing.minCoeff())
      fail("the {} plane '{}' passes through the other cuts: it has no side between them",
           cut.patch, cut.plane.text);
    if (side < 0.0) n = -n;
    // n·(x − p) with x = origin + M·ijk, as a linear function of the voxel index.
    const Eigen::Matrix3d m = frame.index_to_physical();
    mve::ClipPlane clip;
    clip.normal = m.transpose() * n;
    clip.offset = n.dot(frame.origin - cut.plane.point);
    options.clip_planes.push_back(clip);
    Cut oriented = cut;
    oriented.plane.normal = n;
    prepared.oblique.push_back(oriented);
  }
  return prepared;
}

void finish_patches(HybridMesh& mesh, const mve::FieldSource& field, const std::vector<Cut>& cuts,
                    const PreparedCuts& prepared, const std::vector<Region>& regions,
                    const std::string& from_patch) {
  const double tolerance = 1e-6 * field.frame().spacing.minCoeff();
  for (const Cut& cut : prepared.oblique) {
    const int id = mesh.add_patch(cut.patch);
    for_each_boundary_face(mesh, [&](std::span<NodeId> face, std::int32_t& patch) {
      for (NodeId n : face)
        if (std::abs(cut.plane.normal.dot(mesh.nodes[n] - cut.plane.point)) > tolerance) return;
      patch = id;
    });
  }
  const auto report = patch_report(mesh);
  for (const Cut& cut : cuts) {
    const auto it = std::find_if(report.begin(), report.end(),
                                 [&](const PatchReport& r) { return r.name == cut.patch; });
    if (it == report.end() || it->faces == 0) {
      const Eigen::Vector3d& c = prepared.centroid_index;
      const Eigen::Vector3d x = field.frame().physical(c);
      fail(
          "the {} plane '{}' does not cut the object: no boundary face lies on it (the "
          "object's centroid is at voxel i={:.0f} j={:.0f} k={:.0f}, {:.1f},{:.1f},{:.1f} mm)",
          cut.patch, cut.plane.text, c[0], c[1], c[2], x[0], x[1], x[2]);
    }
  }
  const int from = mesh.patch_id(from_patch);
  for (const Region& region : regions) {
    const int id = mesh.add_patch(region.name);
    std::size_t moved = 0;
    for_each_boundary_face(mesh, [&](std::span<NodeId> face, std::int32_t& patch) {
      if (patch != from) return;
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      for (NodeId n : face) c += mesh.nodes[n];
      if (region.contains(c / static_cast<double>(face.size()))) patch = id, ++moved;
    });
    if (moved == 0)
      fail("region '{}' contains no {} face: check its coordinates (millimetres, image frame)",
           region.name, from_patch);
  }
}

std::vector<PatchReport> patch_report(const HybridMesh& mesh) {
  std::vector<PatchReport> report(mesh.patch_names.size());
  std::vector<std::vector<std::uint64_t>> edges(mesh.patch_names.size());  // (min, max) packed
  for (std::size_t p = 0; p < report.size(); ++p) report[p].name = mesh.patch_names[p];
  for_each_boundary_face(mesh, [&](std::span<const NodeId> face, std::int32_t patch) {
    report[patch].faces++;
    report[patch].area += polygon_area(mesh, face);
    for (std::size_t e = 0; e < face.size(); ++e)
      edges[patch].push_back(edge_key(face[e], face[(e + 1) % face.size()]));
  });
  // A patch's perimeter: the edges that only one of its own faces uses.
  for (std::size_t p = 0; p < report.size(); ++p) {
    auto& e = edges[p];
    std::sort(e.begin(), e.end());
    for (std::size_t i = 0; i < e.size();) {
      std::size_t j = i;
      while (j < e.size() && e[j] == e[i]) ++j;
      if (j - i == 1)
        report[p].perimeter += (mesh.nodes[static_cast<NodeId>(e[i] >> 32)] -
                                mesh.nodes[static_cast<NodeId>(e[i] & 0xffffffffu)])
                                   .norm();
      i = j;
    }
  }
  return report;
}

PatchOpenings patch_openings(const HybridMesh& mesh, int patch) {
  // Union–find over the patch's nodes.
  std::vector<NodeId> parent(mesh.nodes.size(), -1);
  const auto root = [&](NodeId n) {
    while (parent[static_cast<std::size_t>(n)] != n) {
      NodeId& p = parent[static_cast<std::size_t>(n)];
      p = parent[static_cast<std::size_t>(p)];
      n = p;
    }
    return n;
  };
  for_each_boundary_face(mesh, [&](std::span<const NodeId> face, std::int32_t id) {
    if (id != patch) return;
    for (NodeId n : face)
      if (parent[static_cast<std::size_t>(n)] < 0) parent[static_cast<std::size_t>(n)] = n;
    for (std::size_t k = 1; k < face.size(); ++k) {
      const NodeId a = root(face[0]), b = root(face[k]);
      if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
    }
  });
  PatchOpenings o;
  std::vector<int> index(mesh.nodes.size(), -1);  // per root
  std::vector<Eigen::Vector3d> moment;
  for_each_boundary_face(mesh, [&](std::span<const NodeId> face, std::int32_t id) {
    if (id != patch) {
      o.of_face.push_back(-1);
      return;
    }
    int& k = index[static_cast<std::size_t>(root(face[0]))];
    if (k < 0) {
      k = static_cast<int>(o.area.size());
      o.area.push_back(0.0);
      moment.push_back(Eigen::Vector3d::Zero());
    }
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (NodeId n : face) c += mesh.nodes[n];
    const double a = polygon_area(mesh, face);
    o.area[static_cast<std::size_t>(k)] += a;
    moment[static_cast<std::size_t>(k)] += a * c / static_cast<double>(face.size());
    o.of_face.push_back(k);
  });
  std::vector<int> order(o.area.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return o.area[static_cast<std::size_t>(a)] > o.area[static_cast<std::size_t>(b)];
  });
  std::vector<int> rank(order.size());
  PatchOpenings sorted;
  for (std::size_t r = 0; r < order.size(); ++r) {
    const auto k = static_cast<std::size_t>(order[r]);
    rank[k] = static_cast<int>(r);
    sorted.area.push_back(o.area[k]);
    sorted.centroid.push_back(moment[k] / o.area[k]);
  }
  sorted.of_face = std::move(o.of_face);
  for (int& k : sorted.of_face)
    if (k >= 0) k = rank[static_cast<std::size_t>(k)];
  return sorted;
}

}  // namespace naris
