#pragma once
// Models as YAML files, and the recording preprocessing of dissertation 5.3.
#include <filesystem>
#include <string>

#include "postproc/olfaction/oe_model.h"
#include "postproc/olfaction/signal.h"

namespace naris::olfaction {

// name, sample_rate_hz, input_unit, output_unit, na, nb, nd, a: [...], b: [...]
void write_model(const std::filesystem::path& path, const OeModel& m,
                 const std::string& comment = "");
OeModel read_model(const std::filesystem::path& path);
// A preset name or a YAML file.
OeModel load_model(const std::string& name_or_path);

// Bessel low-pass at `cutoff_hz` (zero phase) then resampling to `rate_hz` (5.3: 100 Hz, 200 Hz).
// A record already at or below the target rate is only resampled.
Record preprocess(const Record& r, double cutoff_hz = 100.0, double rate_hz = 200.0);

}  // namespace naris::olfaction
