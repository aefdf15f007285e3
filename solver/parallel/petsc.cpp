#include "solver/parallel/petsc.h"

#include <algorithm>
#include <set>

#include "core/error.h"

namespace naris::petsc {
namespace {

std::set<std::string>& defaulted() {
  static std::set<std::string> keys;  // without the leading '-'
  return keys;
}

}  // namespace

void check(PetscErrorCode code, const char* what) {
  if (code == 0) return;
  const char* text = nullptr;
  PetscErrorMessage(code, &text, nullptr);
  fail("PETSc failed in {}: {} (error {})", what, text ? text : "unknown", static_cast<int>(code));
}

void set_default_option(const std::string& key, const char* value) {
  PetscBool set = PETSC_FALSE;
  check(PetscOptionsHasName(nullptr, nullptr, key.c_str(), &set), "PetscOptionsHasName");
  if (set) return;
  check(PetscOptionsSetValue(nullptr, key.c_str(), value), "PetscOptionsSetValue");
  defaulted().insert(key.substr(key.find_first_not_of('-')));
}

std::vector<std::string> unused_options() {
  // Read by PetscFinalize, after any report could be made.
  static const char* const kAtFinalize[] = {"options_left", "malloc_dump", "malloc_view",
                                            "memory_view",  "log_view",    "objects_dump"};
  PetscInt count = 0;
  char **names = nullptr, **values = nullptr;
  check(PetscOptionsLeftGet(nullptr, &count, &names, &values), "PetscOptionsLeftGet");
  std::vector<std::string> unused;
  for (PetscInt i = 0; i < count; ++i) {
    const std::string name = names[i];
    const bool at_finalize = std::any_of(std::begin(kAtFinalize), std::end(kAtFinalize),
                                         [&](const char* f) { return name.rfind(f, 0) == 0; });
    if (at_finalize || defaulted().count(name) > 0) continue;
    unused.push_back("-" + name + (values[i] ? std::string(" ") + values[i] : std::string()));
  }
  check(PetscOptionsLeftRestore(nullptr, &count, &names, &values), "PetscOptionsLeftRestore");
  return unused;
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
