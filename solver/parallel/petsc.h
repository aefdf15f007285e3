#pragma once
// PETSc through small RAII types: a session (PetscInitialize … PetscFinalize) and owning
// handles for Mat, Vec and KSP, so nothing leaks on an error path. Every PETSc error becomes a
// naris::Error carrying PETSc's message.
#include <petscksp.h>

#include <string>
#include <utility>
#include <vector>

namespace naris::petsc {

// Throws naris::Error naming `what` when a PETSc call fails.
void check(PetscErrorCode code, const char* what);

// Initializes PETSc (and MPI, if nobody did) for the lifetime of the object; a second session
// in the same process reuses the first.
class Session {
 public:
  Session(int* argc = nullptr, char*** argv = nullptr);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;
  int rank() const;
  int size() const;

 private:
  bool owns_ = false;
};

// A default of naris's into PETSc's options database, unless the user gave the option: the
// command line still overrides it. Such defaults are left out of unused_options().
void set_default_option(const std::string& key, const char* value);

// The options in the database that nothing has read so far (as "-name value"), leaving out
// naris's own defaults and the options PETSc reads only at PetscFinalize.
std::vector<std::string> unused_options();

// naris's own work as an event of PETSc's profile (`-log_view`), beside PETSc's factorizations
// and Krylov iterations: the time between construction and destruction, under `name`
// (registered at first use; a name already registered is reused, so repeated solves in one
// process add up in one row).
class LoggedEvent {
 public:
  explicit LoggedEvent(const char* name);
  ~LoggedEvent();
  LoggedEvent(const LoggedEvent&) = delete;
  LoggedEvent& operator=(const LoggedEvent&) = delete;

 private:
  PetscLogEvent event_ = -1;
};

template <class H, PetscErrorCode (*Destroy)(H*)>
class Handle {
 public:
  Handle() = default;
  explicit Handle(H h) : h_(h) {}
  ~Handle() { reset(); }
  Handle(Handle&& o) noexcept : h_(std::exchange(o.h_, nullptr)) {}
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      h_ = std::exchange(o.h_, nullptr);
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  void reset() {
    if (h_) Destroy(&h_);
    h_ = nullptr;
  }
  H get() const { return h_; }
  operator H() const { return h_; }  // NOLINT: handles pass straight to PETSc calls
  H* out() {
    reset();
    return &h_;
  }

 private:
  H h_ = nullptr;
};

using Matrix = Handle<Mat, MatDestroy>;
using Vector = Handle<Vec, VecDestroy>;
using LinearSolver = Handle<KSP, KSPDestroy>;
using Scatter = Handle<VecScatter, VecScatterDestroy>;
using IndexSet = Handle<IS, ISDestroy>;

}  // namespace naris::petsc
