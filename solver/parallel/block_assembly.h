#pragma once
// Element matrices added straight into the value arrays of a 4×4-block PETSc matrix (BAIJ,
// sequential or MPI) once its nonzero pattern is final. MatSetValuesBlocked searches every
// block's column in its row and transposes the caller's row-major values block by block, a
// large share of each assembly (docs/results/solver-choices.md). Here each column is found by a
// binary search in the row's sorted block columns and each block column of the element matrix
// (column-major, as the element kernels build it) lands as four contiguous values — PETSc
// stores a block column-major too. Rows another rank owns still go through
// MatSetValuesBlocked and its stash, as do all rows before the first assembly (the pattern is
// only known after it) and every matrix type but BAIJ (`-ns_mat_type aij`).
#include <petscmat.h>

#include <span>
#include <vector>

#include "solver/parallel/partition.h"

namespace naris::parallel {

class BlockAssembly {
 public:
  BlockAssembly(Mat matrix, const NodeNumbering& numbering);
  ~BlockAssembly();
  BlockAssembly(const BlockAssembly&) = delete;
  BlockAssembly& operator=(const BlockAssembly&) = delete;

  // Opens the matrix's arrays for adding (after MatZeroEntries); end() closes them and must
  // come before MatAssemblyBegin. The assembly that follows is not optional: it sends the rows
  // of other ranks and raises the matrix's state, by which preconditioners see new values.
  void begin();
  void end();
  // Adds K (4n × 4n, column-major, unknowns (u, v, w, p) interleaved per node) into the rows
  // and columns of `nodes` (local numbers).
  void add(std::span<const NodeId> nodes, const double* K);
  // Between begin() and end(): whether the owned rows go straight into the arrays.
  bool adds_directly() const { return direct_; }

 private:
  double* find(NodeId row, NodeId column) const;
  void add_through_petsc(std::span<const NodeId> nodes, std::size_t first, std::size_t last,
                         const double* K);

  Mat matrix_;
  const NodeNumbering& numbering_;
  bool baij_ = false;
  bool direct_ = false;  // between begin() and end() of an assembled BAIJ matrix
  Mat diagonal_ = nullptr, off_diagonal_ = nullptr;  // the owned columns and the others
  const PetscInt *diagonal_row_ = nullptr, *diagonal_column_ = nullptr;
  const PetscInt *off_row_ = nullptr, *off_column_ = nullptr;
  PetscScalar *diagonal_values_ = nullptr, *off_values_ = nullptr;
  std::vector<PetscInt> halo_column_;  // per halo node: its column in the off-diagonal part
  bool halo_mapped_ = false;
  std::vector<PetscInt> global_;    // scratch: global block numbers of an element
  std::vector<double> row_values_;  // scratch: block rows, row-major, for PETSc
};

}  // namespace naris::parallel
