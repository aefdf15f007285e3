// The pieces the ranks keep of a mesh (parallel/partition.h): every cell and boundary face has
// one owner, every owned node keeps all its cells and so does every node of an owned cell (the
// recovered gradient there needs them), and a field cut into pieces and gathered is the field.
#include <gtest/gtest.h>

#include <map>
#include <set>

#include "solver/nonlinear/navier_stokes_solver.h"
#include "solver/ns/distributed_field.h"
#include "solver/parallel/partition.h"
#include "tests/solver/meshes.h"

namespace naris::parallel {
namespace {

// The cells around each node, as sorted global node lists (a cell's identity across pieces).
using CellKey = std::vector<NodeId>;
template <class Cells>
void add_cells(const Cells& cells, const std::vector<NodeId>& global,
               std::map<NodeId, std::set<CellKey>>& around, std::set<CellKey>* all) {
  for (const auto& c : cells) {
    CellKey key;
    for (NodeId v : c) key.push_back(global.empty() ? v : global[static_cast<std::size_t>(v)]);
    std::sort(key.begin(), key.end());
    for (NodeId g : key) around[g].insert(key);
    if (all) all->insert(key);
  }
}

TEST(Partition, PiecesShareTheMeshWithoutGapsOrOverlaps) {
  const HybridMesh whole = testing::convergence_mesh("mve-ball", 8);
  ASSERT_GT(whole.tets.size() * whole.pyramids.size() * whole.hexes.size(), 0u);
  std::map<NodeId, std::set<CellKey>> around;
  add_cells(whole.tets, {}, around, nullptr);
  add_cells(whole.pyramids, {}, around, nullptr);
  add_cells(whole.hexes, {}, around, nullptr);
  const std::size_t faces = whole.boundary_tris.size() + whole.boundary_quads.size();
  for (int ranks : {1, 2, 3}) {
    std::size_t owned_cells = 0, owned_nodes = 0;
    std::vector<int> face_owners(faces, 0);
    for (int rank = 0; rank < ranks; ++rank) {
      const MeshPiece piece = mesh_piece(whole, rank, ranks);
      const NodeNumbering& num = piece.numbering;
      ASSERT_EQ(num.global.size(), piece.mesh.nodes.size());
      EXPECT_EQ(num.global_nodes, whole.nodes.size());
      owned_nodes += static_cast<std::size_t>(num.owned);
      for (std::size_t l = 0; l < num.global.size(); ++l) {
        const auto g = static_cast<std::size_t>(num.global[l]);
        EXPECT_EQ(piece.mesh.nodes[l], whole.nodes[g]);
        EXPECT_EQ(num.owns(static_cast<NodeId>(l)), num.range.contains(num.global[l]));
        EXPECT_EQ(num.to_local(num.global[l]), static_cast<NodeId>(l));
      }
      // A node the piece does not hold has no local number.
      std::vector<char> held(whole.nodes.size(), 0);
      for (NodeId g : num.global) held[static_cast<std::size_t>(g)] = 1;
      for (std::size_t g = 0; g < held.size(); ++g)
        if (!held[g]) {
          EXPECT_EQ(num.to_local(static_cast<NodeId>(g)), -1) << g;
        }
      std::map<NodeId, std::set<CellKey>> kept;
      add_cells(piece.mesh.tets, num.global, kept, nullptr);
      add_cells(piece.mesh.pyramids, num.global, kept, nullptr);
      add_cells(piece.mesh.hexes, num.global, kept, nullptr);
      // Complete neighbourhoods of the owned nodes and of the nodes of owned cells.
      auto count_owned = [&](const auto& cells) {
        for (const auto& c : cells) {
          if (!num.owns_cell(c)) continue;
          ++owned_cells;
          for (NodeId v : c) {
            const NodeId g = num.global[static_cast<std::size_t>(v)];
            EXPECT_EQ(kept[g], around[g]) << "node " << g << " on rank " << rank;
          }
        }
      };
      count_owned(piece.mesh.tets);
      count_owned(piece.mesh.pyramids);
      count_owned(piece.mesh.hexes);
      for (NodeId g = num.range.first; g < num.range.end; ++g) EXPECT_EQ(kept[g], around[g]);
      ASSERT_EQ(piece.face_index.size(),
                piece.mesh.boundary_tris.size() + piece.mesh.boundary_quads.size());
      for (std::size_t f = 0; f < piece.face_index.size(); ++f) ++face_owners[piece.face_index[f]];
      // A face keeps its nodes and patch.
      for (std::size_t f = 0; f < piece.mesh.boundary_tris.size(); ++f) {
        const std::size_t w = piece.face_index[f];
        ASSERT_LT(w, whole.boundary_tris.size());
        for (int i = 0; i < 3; ++i)
          EXPECT_EQ(num.global[static_cast<std::size_t>(piece.mesh.boundary_tris[f][i])],
                    whole.boundary_tris[w][i]);
        EXPECT_EQ(piece.mesh.boundary_tri_patch[f], whole.boundary_tri_patch[w]);
      }
    }
    EXPECT_EQ(owned_nodes, whole.nodes.size()) << ranks << " ranks";
    EXPECT_EQ(owned_cells, whole.cell_count()) << ranks << " ranks";
    EXPECT_EQ(std::count(face_owners.begin(), face_owners.end(), 1),
              static_cast<std::ptrdiff_t>(faces))
        << ranks << " ranks";
  }
}

TEST(Partition, AFieldOnThePiecesIsTheWholeField) {
  const HybridMesh whole = testing::convergence_mesh("hex", 4);
  ns::FlowField field;
  for (std::size_t k = 0; k < whole.nodes.size(); ++k) {
    field.velocity.push_back(whole.nodes[k] * 2.0);
    field.pressure.push_back(whole.nodes[k].sum());
  }
  const MeshPiece piece = mesh_piece(whole, 1, 3);
  const ns::FlowField local = ns::local_field(field, piece.numbering);
  ASSERT_EQ(local.pressure.size(), piece.mesh.nodes.size());
  for (std::size_t l = 0; l < local.pressure.size(); ++l) {
    EXPECT_EQ(local.velocity[l], piece.mesh.nodes[l] * 2.0);
    EXPECT_EQ(local.pressure[l], piece.mesh.nodes[l].sum());
  }
  // Conditions on halo nodes stay (the iterate holds them there too); those off the piece go.
  ns::DirichletConditions bc;
  for (NodeId g = 0; g < static_cast<NodeId>(whole.nodes.size()); ++g) {
    bc.nodes.push_back(g);
    bc.values.push_back(field.velocity[static_cast<std::size_t>(g)]);
  }
  bc.pressure_pin = {0, 1.5};
  const ns::DirichletConditions lbc = ns::local_conditions(bc, piece.numbering);
  ASSERT_EQ(lbc.nodes.size(), piece.mesh.nodes.size());
  for (std::size_t k = 0; k < lbc.nodes.size(); ++k)
    EXPECT_EQ(lbc.values[k], piece.mesh.nodes[static_cast<std::size_t>(lbc.nodes[k])] * 2.0);
  EXPECT_EQ(lbc.pressure_pin.has_value(),
            std::find(piece.numbering.global.begin(), piece.numbering.global.end(), 0) !=
                piece.numbering.global.end());
  // One rank: gathering is the identity.
  const ns::FlowField back =
      ns::gather_field(ns::local_field(field, whole_numbering(whole.nodes.size())),
                       whole_numbering(whole.nodes.size()), MPI_COMM_SELF);
  EXPECT_EQ(back.pressure, field.pressure);
  EXPECT_EQ(back.velocity, field.velocity);
}

}  // namespace
}  // namespace naris::parallel
