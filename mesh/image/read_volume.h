#pragma once
// Reads a 3D image through VTK's readers: NRRD (.nrrd/.nhdr, raw or gzip, 3D Slicer
// segmentations), NIfTI (.nii/.nii.gz), MetaImage (.mha/.mhd), VTK image data (.vti) and a
// folder of DICOM slices. Keeps the physical frame (origin, spacing, direction).
#include <filesystem>
#include <map>
#include <string>

#include "mesh/image/volume.h"

namespace naris {

struct VolumeInfo {
  std::string format;      // "nrrd", "nifti", ...
  std::string pixel_type;  // the file's scalar type, e.g. "uint8"
  double min_value = 0.0;
  double max_value = 0.0;
  // Segment names of a 3D Slicer segmentation NRRD (SegmentN_Name / SegmentN_LabelValue), by
  // label value; empty when the file names none.
  std::map<int, std::string> label_names;
};

// Throws naris::Error naming the file and the problem (missing, truncated, corrupt, unsupported
// pixel type, not 3D, non-finite values).
Volume<float> read_volume(const std::filesystem::path& path, VolumeInfo* info = nullptr);

}  // namespace naris
