#pragma once
// The figures of naris trace: paths.png (the paths over the airway) and crossings.png (where
// they cross each plane, inside its outline).
#include <filesystem>

#include "solver/particles/trace_job.h"

namespace naris::app {

void write_trace_figures(const particles::TraceResult& result, const std::filesystem::path& out);

}  // namespace naris::app
