#pragma once
// Volumes written as gzip-compressed NRRD with their LPS frame, so 3D Slicer, ParaView and our
// own reader open them in place. Written atomically: a temporary name, renamed when complete.
#include <cstdint>
#include <filesystem>

#include "mesh/image/volume.h"

namespace naris {

// A 0/1 labelmap (uint8): 3D Slicer opens it as a segmentation.
void write_labelmap_nrrd(const Volume<std::uint8_t>& mask, const std::filesystem::path& path);

// A CT volume in Hounsfield units, rounded to int16 (clamped to its range) like a scanner's.
void write_ct_nrrd(const Volume<float>& ct, const std::filesystem::path& path);

// Any scalar field (a signed distance, a smoothed indicator) as float32, values unchanged.
void write_field_nrrd(const Volume<float>& field, const std::filesystem::path& path);

}  // namespace naris
