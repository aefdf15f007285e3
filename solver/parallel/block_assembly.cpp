#include "solver/parallel/block_assembly.h"

#include <algorithm>

#include "core/error.h"
#include "solver/parallel/petsc.h"

namespace naris::parallel {

namespace {

// A block's 16 values: PETSc stores block (i, j) column-major, value (c, d) at 4d + c, which is
// how column 4j + d of a column-major element matrix holds rows 4i … 4i + 3.
inline void add_block(double* to, const double* K, std::size_t ld, std::size_t i, std::size_t j) {
  for (std::size_t d = 0; d < 4; ++d) {
    const double* from = K + (4 * j + d) * ld + 4 * i;
    for (std::size_t c = 0; c < 4; ++c) to[4 * d + c] += from[c];
  }
}

}  // namespace

BlockAssembly::BlockAssembly(Mat matrix, const NodeNumbering& numbering)
    : matrix_(matrix), numbering_(numbering) {
  PetscBool baij = PETSC_FALSE;
  petsc::check(PetscObjectTypeCompareAny(reinterpret_cast<PetscObject>(matrix), &baij, MATSEQBAIJ,
                                         MATMPIBAIJ, ""),
               "PetscObjectTypeCompareAny");
  PetscInt bs = 1;
  petsc::check(MatGetBlockSize(matrix, &bs), "MatGetBlockSize");
  baij_ = baij && bs == 4;
}

BlockAssembly::~BlockAssembly() {
  // An error between begin() and end() leaves the arrays open; give them back.
  if (direct_) {
    try {
      end();
    } catch (...) {
    }
  }
}

void BlockAssembly::begin() {
  PetscBool assembled = PETSC_FALSE;
  petsc::check(MatAssembled(matrix_, &assembled), "MatAssembled");
  direct_ = baij_ && assembled;
  if (!direct_) return;
  PetscBool mpi = PETSC_FALSE;
  petsc::check(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(matrix_), MATMPIBAIJ, &mpi),
               "PetscObjectTypeCompare");
  const PetscInt* garray = nullptr;
  if (mpi) {
    petsc::check(MatMPIBAIJGetSeqBAIJ(matrix_, &diagonal_, &off_diagonal_, &garray),
                 "MatMPIBAIJGetSeqBAIJ");
  } else {
    diagonal_ = matrix_;
    off_diagonal_ = nullptr;
  }
  PetscInt rows = 0;
  PetscBool done = PETSC_FALSE;
  petsc::check(MatGetRowIJ(diagonal_, 0, PETSC_FALSE, PETSC_TRUE, &rows, &diagonal_row_,
                           &diagonal_column_, &done),
               "MatGetRowIJ");
  if (!done || rows != numbering_.owned)
    fail("internal: the matrix's block rows ({}) are not this rank's {} nodes", rows,
         numbering_.owned);
  petsc::check(MatSeqBAIJGetArray(diagonal_, &diagonal_values_), "MatSeqBAIJGetArray");
  if (off_diagonal_) {
    petsc::check(MatGetRowIJ(off_diagonal_, 0, PETSC_FALSE, PETSC_TRUE, &rows, &off_row_,
                             &off_column_, &done),
                 "MatGetRowIJ");
    if (!done) fail("internal: no row structure for the off-diagonal block");
    petsc::check(MatSeqBAIJGetArray(off_diagonal_, &off_values_), "MatSeqBAIJGetArray");
    // The off-diagonal part numbers its columns by position in garray (the sorted global
    // numbers of the columns it holds); the halo's local numbers follow global order too. The
    // pattern is fixed after the first assembly, and with it this map.
    if (halo_mapped_) return;
    halo_mapped_ = true;
    PetscInt columns = 0;
    petsc::check(MatGetLocalSize(off_diagonal_, nullptr, &columns), "MatGetLocalSize");
    const PetscInt* last = garray + columns / 4;
    const std::size_t halo = numbering_.global.size() - static_cast<std::size_t>(numbering_.owned);
    halo_column_.assign(halo, -1);
    for (std::size_t h = 0; h < halo; ++h) {
      const PetscInt g = numbering_.global[static_cast<std::size_t>(numbering_.owned) + h];
      const PetscInt* at = std::lower_bound(garray, last, g);
      if (at != last && *at == g) halo_column_[h] = static_cast<PetscInt>(at - garray);
    }
  }
}

void BlockAssembly::end() {
  if (!direct_) return;
  direct_ = false;
  PetscInt rows = 0;
  PetscBool done = PETSC_FALSE;
  petsc::check(MatSeqBAIJRestoreArray(diagonal_, &diagonal_values_), "MatSeqBAIJRestoreArray");
  petsc::check(MatRestoreRowIJ(diagonal_, 0, PETSC_FALSE, PETSC_TRUE, &rows, &diagonal_row_,
                               &diagonal_column_, &done),
               "MatRestoreRowIJ");
  if (off_diagonal_) {
    petsc::check(MatSeqBAIJRestoreArray(off_diagonal_, &off_values_), "MatSeqBAIJRestoreArray");
    petsc::check(MatRestoreRowIJ(off_diagonal_, 0, PETSC_FALSE, PETSC_TRUE, &rows, &off_row_,
                                 &off_column_, &done),
                 "MatRestoreRowIJ");
  }
}

double* BlockAssembly::find(NodeId row, NodeId column) const {
  const auto r = static_cast<std::size_t>(row);
  const PetscInt *first, *last, *columns;
  PetscInt wanted;
  PetscScalar* values;
  if (numbering_.owns(column)) {
    columns = diagonal_column_;
    first = columns + diagonal_row_[r];
    last = columns + diagonal_row_[r + 1];
    wanted = column;
    values = diagonal_values_;
  } else {
    columns = off_column_;
    first = columns + off_row_[r];
    last = columns + off_row_[r + 1];
    wanted = halo_column_[static_cast<std::size_t>(column - numbering_.owned)];
    values = off_values_;
  }
  const PetscInt* at = std::lower_bound(first, last, wanted);
  if (at == last || *at != wanted)
    fail("internal: block ({}, {}) is outside the matrix's nonzero pattern",
         numbering_.to_global(row), numbering_.to_global(column));
  return values + 16 * (at - columns);
}

void BlockAssembly::add(std::span<const NodeId> nodes, const double* K) {
  const std::size_t n = nodes.size(), ld = 4 * n;
  global_.clear();  // filled by the first row that goes through PETSc
  if (!direct_) {
    add_through_petsc(nodes, 0, n, K);
    return;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const NodeId row = nodes[i];
    if (!numbering_.owns(row)) {
      add_through_petsc(nodes, i, i + 1, K);
      continue;
    }
    for (std::size_t j = 0; j < n; ++j) add_block(find(row, nodes[j]), K, ld, i, j);
  }
}

// Block rows [first, last) of K through MatSetValuesBlocked (row-major values, as PETSc reads
// them).
void BlockAssembly::add_through_petsc(std::span<const NodeId> nodes, std::size_t first,
                                      std::size_t last, const double* K) {
  const std::size_t n = nodes.size(), ld = 4 * n;
  if (global_.empty())
    for (NodeId v : nodes) global_.push_back(numbering_.to_global(v));
  row_values_.resize(4 * (last - first) * ld);
  for (std::size_t r = 4 * first; r < 4 * last; ++r)
    for (std::size_t col = 0; col < ld; ++col)
      row_values_[(r - 4 * first) * ld + col] = K[col * ld + r];
  petsc::check(
      MatSetValuesBlocked(matrix_, static_cast<PetscInt>(last - first), &global_[first],
                          static_cast<PetscInt>(n), global_.data(), row_values_.data(), ADD_VALUES),
      "MatSetValuesBlocked");
}

}  // namespace naris::parallel
