#include "solver/parallel/petsc.h"

#include "core/error.h"

namespace naris::petsc {

void check(PetscErrorCode code, const char* what) {
  if (code == 0) return;
  const char* text = nullptr;
  PetscErrorMessage(code, &text, nullptr);
  fail("PETSc failed in {}: {} (error {})", what, text ? text : "unknown", static_cast<int>(code));
}

Session::Session(int* argc, char*** argv) {
  PetscBool initialized = PETSC_FALSE;
  PetscInitialized(&initialized);
  if (initialized) return;
  // PETSc's own error handler would print a traceback and abort; naris reports errors itself.
  check(PetscInitialize(argc, argv, nullptr, nullptr), "PetscInitialize");
  PetscPushErrorHandler(PetscReturnErrorHandler, nullptr);
  owns_ = true;
}

Session::~Session() {
  if (owns_) PetscFinalize();
}

int Session::rank() const {
  int r = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &r);
  return r;
}

int Session::size() const {
  int s = 1;
  MPI_Comm_size(PETSC_COMM_WORLD, &s);
  return s;
}

LoggedEvent::LoggedEvent(const char* name) {
  check(PetscLogEventGetId(name, &event_), "PetscLogEventGetId");
  if (event_ < 0) check(PetscLogEventRegister(name, PETSC_OBJECT_CLASSID, &event_), name);
  check(PetscLogEventBegin(event_, nullptr, nullptr, nullptr, nullptr), name);
}

LoggedEvent::~LoggedEvent() {
  PetscLogEventEnd(event_, nullptr, nullptr, nullptr, nullptr);
}

}  // namespace naris::petsc
