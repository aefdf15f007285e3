#include "solver/airflow/solution_file.h"

#include <fmt/format.h>

#include <sstream>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/hdf5_table.h"
#include "mesh/io/mesh_h5.h"

namespace naris::airflow {
using continuation::ContinuationState;
using ns::FlowField;
namespace fs = std::filesystem;

namespace {

constexpr int kVersion = 1;
constexpr const char* kKind = "a naris solution file";

void attribute(hid_t file, const char* name, double value, const fs::path& path) {
  write_string_attribute(file, name, fmt::format("{:.17g}", value), path);
}

double number_attribute(hid_t file, const char* name, const fs::path& path) {
  const std::string text = read_string_attribute(file, name, path, kKind);
  try {
    return std::stod(text);
  } catch (const std::exception&) {
    fail("{}: attribute {} is not a number ('{}')", path.string(), name, text);
  }
}

void write_fields(hid_t file, const char* velocity, const char* pressure, const FlowField& f,
                  double u_scale, double p_scale, const fs::path& path) {
  std::vector<double> u(3 * f.velocity.size()), p(f.pressure.size());
  for (std::size_t n = 0; n < f.velocity.size(); ++n) {
    for (int c = 0; c < 3; ++c) u[3 * n + static_cast<std::size_t>(c)] = f.velocity[n][c] * u_scale;
    p[n] = f.pressure[n] * p_scale;
  }
  write_table(file, velocity, H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, u.data(), f.velocity.size(), 3,
              path);
  write_table(file, pressure, H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, p.data(), p.size(), 1, path);
}

FlowField read_fields(hid_t file, const char* velocity, const char* pressure,
                      const fs::path& path) {
  FlowField f;
  read_table(file, velocity, H5T_NATIVE_DOUBLE, 3, f.velocity, path);
  read_table(file, pressure, H5T_NATIVE_DOUBLE, 1, f.pressure, path);
  if (f.velocity.size() != f.pressure.size())
    fail("{}: {} and {} sizes differ", path.string(), velocity, pressure);
  for (std::size_t n = 0; n < f.pressure.size(); ++n)
    if (!std::isfinite(f.pressure[n]) || !f.velocity[n].allFinite())
      fail("{}: a non-finite value at node {} of {}", path.string(), n, velocity);
  return f;
}

void write_xdmf(const MeshCounts& mesh, const fs::path& h5, const fs::path& mesh_file) {
  const fs::path folder = fs::absolute(h5).parent_path();
  const std::string m = fs::relative(fs::absolute(mesh_file), folder).string();
  const std::string s = h5.filename().string();
  const std::size_t n = mesh.nodes;
  std::ostringstream x;
  x << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n <Domain>\n"
    << " <Grid Name=\"solution\" GridType=\"Collection\" CollectionType=\"Spatial\">\n";
  auto grid = [&](const char* name, const char* topology, std::size_t count, int per,
                  const char* dataset) {
    if (count == 0) return;
    x << "  <Grid Name=\"" << name << "\" GridType=\"Uniform\">\n   <Topology TopologyType=\""
      << topology << "\" NumberOfElements=\"" << count << "\"><DataItem Dimensions=\"" << count
      << " " << per << "\" NumberType=\"Int\" Precision=\"4\" Format=\"HDF\">" << m << ":"
      << dataset << "</DataItem></Topology>\n"
      << "   <Geometry GeometryType=\"XYZ\"><DataItem Dimensions=\"" << n
      << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << m
      << ":/nodes</DataItem></Geometry>\n";
    for (const char* field : {"velocity", "velocity_nondimensional"})
      x << "   <Attribute Name=\"" << field
        << "\" AttributeType=\"Vector\" Center=\"Node\"><DataItem Dimensions=\"" << n
        << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << s << ":/" << field
        << "</DataItem></Attribute>\n";
    for (const char* field : {"pressure", "pressure_nondimensional"})
      x << "   <Attribute Name=\"" << field
        << "\" AttributeType=\"Scalar\" Center=\"Node\"><DataItem Dimensions=\"" << n
        << "\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << s << ":/" << field
        << "</DataItem></Attribute>\n";
    x << "  </Grid>\n";
  };
  grid("tetrahedra", "Tetrahedron", mesh.tets, 4, "/cells/tet");
  grid("pyramids", "Pyramid", mesh.pyramids, 5, "/cells/pyramid");
  grid("hexahedra", "Hexahedron", mesh.hexes, 8, "/cells/hex");
  x << " </Grid>\n </Domain>\n</Xdmf>\n";
  write_text_file(fs::path(h5).replace_extension(".xdmf"), x.str());
}

}  // namespace

MeshCounts mesh_counts(const HybridMesh& mesh) {
  return {mesh.nodes.size(), mesh.tets.size(), mesh.pyramids.size(), mesh.hexes.size()};
}

std::uint64_t mesh_fingerprint(const HybridMesh& mesh) {
  std::uint64_t h = 1469598103934665603ull;
  auto bytes = [&h](const void* data, std::size_t size) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) h = (h ^ p[i]) * 1099511628211ull;
  };
  bytes(mesh.nodes.data(), mesh.nodes.size() * sizeof(Eigen::Vector3d));
  bytes(mesh.tets.data(), mesh.tets.size() * sizeof(mesh.tets[0]));
  bytes(mesh.pyramids.data(), mesh.pyramids.size() * sizeof(mesh.pyramids[0]));
  bytes(mesh.hexes.data(), mesh.hexes.size() * sizeof(mesh.hexes[0]));
  return h;
}

void write_solution_h5(const SolutionState& s, const fs::path& path, const MeshCounts* mesh,
                       const fs::path& mesh_file) {
  SilenceHdf5 quiet;
  {
    AtomicOutput out(path);
    H5Handle file = create_file(out.temp_path(), path, "naris-solution", kVersion);
    write_string_attribute(file.get(), "mesh_fingerprint",
                           fmt::format("{:016x}", s.mesh_fingerprint), path);
    attribute(file.get(), "nodes", static_cast<double>(s.field.pressure.size()), path);
    attribute(file.get(), "reynolds", s.reynolds, path);
    attribute(file.get(), "target_reynolds", s.target_reynolds, path);
    attribute(file.get(), "u_in", s.u_in, path);
    attribute(file.get(), "d_in_mm", s.d_in_mm, path);
    attribute(file.get(), "density", s.density, path);
    attribute(file.get(), "viscosity", s.viscosity, path);
    write_fields(file.get(), "velocity_nondimensional", "pressure_nondimensional", s.field, 1.0,
                 1.0, path);
    if (mesh) {
      write_fields(file.get(), "velocity", "pressure", s.field, s.u_in, s.density * s.u_in * s.u_in,
                   path);
      write_string_attribute(
          file.get(), "mesh_file",
          fs::relative(fs::absolute(mesh_file), fs::absolute(path).parent_path()).string(), path);
    }
    const ContinuationState& c = s.continuation;
    if (c.next_step > 0.0) {
      attribute(file.get(), "next_step", c.next_step, path);
      attribute(file.get(), "pseudo_time", c.pseudo_time ? 1.0 : 0.0, path);
      attribute(file.get(), "earlier_reynolds", c.earlier_reynolds, path);
      if (c.arclength_step > 0.0) attribute(file.get(), "arclength_step", c.arclength_step, path);
      if (c.earlier_reynolds > 0.0)
        write_fields(file.get(), "earlier_velocity_nondimensional",
                     "earlier_pressure_nondimensional", c.earlier, 1.0, 1.0, path);
    }
    check(H5Fflush(file.get(), H5F_SCOPE_GLOBAL), path, "flush");
    file.reset();
    out.commit();
  }
  if (mesh) write_xdmf(*mesh, path, mesh_file);
}

SolutionState read_solution_h5(const fs::path& path) {
  SilenceHdf5 quiet;
  const H5Handle file = open_file(path, "naris-solution", kVersion, kKind);
  SolutionState s;
  s.mesh_fingerprint =
      std::stoull(read_string_attribute(file.get(), "mesh_fingerprint", path, kKind), nullptr, 16);
  s.reynolds = number_attribute(file.get(), "reynolds", path);
  s.target_reynolds = number_attribute(file.get(), "target_reynolds", path);
  s.u_in = number_attribute(file.get(), "u_in", path);
  s.d_in_mm = number_attribute(file.get(), "d_in_mm", path);
  s.density = number_attribute(file.get(), "density", path);
  s.viscosity = number_attribute(file.get(), "viscosity", path);
  s.field = read_fields(file.get(), "velocity_nondimensional", "pressure_nondimensional", path);
  if (H5Aexists(file.get(), "mesh_file") > 0)
    s.mesh_file = fs::absolute(path).parent_path() /
                  read_string_attribute(file.get(), "mesh_file", path, kKind);
  if (H5Aexists(file.get(), "next_step") > 0) {
    ContinuationState& c = s.continuation;
    c.next_step = number_attribute(file.get(), "next_step", path);
    c.pseudo_time = number_attribute(file.get(), "pseudo_time", path) != 0.0;
    c.earlier_reynolds = number_attribute(file.get(), "earlier_reynolds", path);
    if (H5Aexists(file.get(), "arclength_step") > 0) {
      // Around a turning point the branch's earlier point may lie above in Re.
      c.arclength_step = number_attribute(file.get(), "arclength_step", path);
      if (!(c.arclength_step > 0.0) || !(c.earlier_reynolds > 0.0) ||
          c.earlier_reynolds == s.reynolds)
        fail(
            "{}: an inconsistent arclength state (step {}, earlier Re {} at Re {}: the step must "
            "be positive and the earlier point another)",
            path.string(), c.arclength_step, c.earlier_reynolds, s.reynolds);
    } else if (!(c.next_step > 0.0) || !(c.earlier_reynolds >= 0.0) ||
               c.earlier_reynolds >= s.reynolds) {
      fail(
          "{}: an inconsistent continuation state (next step {}, earlier Re {} at Re {}: the "
          "step must be positive and the earlier Re lower)",
          path.string(), c.next_step, c.earlier_reynolds, s.reynolds);
    }
    if (c.earlier_reynolds > 0.0) {
      c.earlier = read_fields(file.get(), "earlier_velocity_nondimensional",
                              "earlier_pressure_nondimensional", path);
      if (c.earlier.pressure.size() != s.field.pressure.size())
        fail("{}: the earlier step has {} nodes, the solution {}", path.string(),
             c.earlier.pressure.size(), s.field.pressure.size());
    }
  }
  return s;
}

SolvedMesh read_solved_mesh(const std::filesystem::path& solution,
                            const std::filesystem::path& mesh_file) {
  return attach_mesh(read_solution_h5(solution), solution, mesh_file);
}

SolvedMesh attach_mesh(SolutionState state, const std::filesystem::path& solution,
                       const std::filesystem::path& mesh_file) {
  SolvedMesh r;
  r.state = std::move(state);
  r.mesh_file = mesh_file.empty() ? r.state.mesh_file : mesh_file;
  if (r.mesh_file.empty())
    fail("{}: the solution names no mesh file; give the mesh", solution.string());
  r.mesh = read_mesh_h5(r.mesh_file);
  const std::uint64_t fingerprint = mesh_fingerprint(r.mesh);
  if (fingerprint != r.state.mesh_fingerprint ||
      r.mesh.nodes.size() != r.state.field.velocity.size())
    fail("{} was not solved on {} (mesh fingerprints {:016x} and {:016x})", solution.string(),
         r.mesh_file.string(), r.state.mesh_fingerprint, fingerprint);
  r.velocity.assign(r.state.field.velocity.begin(), r.state.field.velocity.end());
  for (Eigen::Vector3d& u : r.velocity) u *= r.state.u_in;
  return r;
}

}  // namespace naris::airflow
