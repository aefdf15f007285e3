#pragma once
// Writes a minimal CT series as DICOM files (explicit VR little endian), one file per slice,
// for testing the DICOM input path without shipping data.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace naris::testing {

class DicomSlice {
 public:
  void element(std::uint16_t group, std::uint16_t tag, const char vr[2], const std::string& value) {
    std::string v = value;
    if (v.size() % 2) v += (std::string(vr) == "UI" ? '\0' : ' ');
    put16(group);
    put16(tag);
    out_ += std::string(vr, 2);
    const std::string vrs(vr, 2);
    if (vrs == "OB" || vrs == "OW" || vrs == "UN" || vrs == "SQ") {
      put16(0);
      put32(static_cast<std::uint32_t>(v.size()));
    } else {
      put16(static_cast<std::uint16_t>(v.size()));
    }
    out_ += v;
  }
  void us(std::uint16_t group, std::uint16_t tag, std::uint16_t value) {
    element(group, tag, "US", std::string(reinterpret_cast<const char*>(&value), 2));
  }
  std::string bytes() const { return out_; }

 private:
  void put16(std::uint16_t v) { out_.append(reinterpret_cast<const char*>(&v), 2); }
  void put32(std::uint32_t v) { out_.append(reinterpret_cast<const char*>(&v), 4); }
  std::string out_;
};

// DICOM decimal strings are at most 16 characters.
inline std::string fmt_ds(double v) {
  std::string s = std::to_string(v);
  return s.substr(0, 16);
}

// Slice k of `values` (nx·ny int16 each) at z = z0 + k·dz.
inline void write_dicom_series(const std::filesystem::path& folder, int nx, int ny,
                               const std::vector<std::vector<std::int16_t>>& slices, double dx,
                               double dy, const std::vector<double>& z) {
  std::filesystem::create_directories(folder);
  for (std::size_t k = 0; k < slices.size(); ++k) {
    DicomSlice meta, data;
    const std::string sop = "1.2.826.0.1.3680043.2.1125.1." + std::to_string(k + 1);
    meta.element(0x0002, 0x0001, "OB", std::string("\0\1", 2));
    meta.element(0x0002, 0x0002, "UI", "1.2.840.10008.5.1.4.1.1.2");
    meta.element(0x0002, 0x0003, "UI", sop);
    meta.element(0x0002, 0x0010, "UI", "1.2.840.10008.1.2.1");
    const std::string meta_bytes = meta.bytes();
    DicomSlice group_length;
    const auto len = static_cast<std::uint32_t>(meta_bytes.size());
    group_length.element(0x0002, 0x0000, "UL", std::string(reinterpret_cast<const char*>(&len), 4));

    data.element(0x0008, 0x0016, "UI", "1.2.840.10008.5.1.4.1.1.2");
    data.element(0x0008, 0x0018, "UI", sop);
    data.element(0x0008, 0x0060, "CS", "CT");
    data.element(0x0010, 0x0010, "PN", "PHANTOM");
    data.element(0x0018, 0x0050, "DS", "3");
    data.element(0x0020, 0x000D, "UI", "1.2.826.0.1.3680043.2.1125.2");
    data.element(0x0020, 0x000E, "UI", "1.2.826.0.1.3680043.2.1125.3");
    data.element(0x0020, 0x0013, "IS", std::to_string(k + 1));
    data.element(0x0020, 0x0032, "DS", "-10\\-20\\" + fmt_ds(z[k]));
    data.element(0x0020, 0x0037, "DS", "1\\0\\0\\0\\1\\0");
    data.us(0x0028, 0x0002, 1);
    data.element(0x0028, 0x0004, "CS", "MONOCHROME2");
    data.us(0x0028, 0x0010, static_cast<std::uint16_t>(ny));
    data.us(0x0028, 0x0011, static_cast<std::uint16_t>(nx));
    data.element(0x0028, 0x0030, "DS", fmt_ds(dy) + "\\" + fmt_ds(dx));
    data.us(0x0028, 0x0100, 16);
    data.us(0x0028, 0x0101, 16);
    data.us(0x0028, 0x0102, 15);
    data.us(0x0028, 0x0103, 1);
    data.element(0x0028, 0x1052, "DS", "-1024");
    data.element(0x0028, 0x1053, "DS", "1");
    data.element(
        0x7FE0, 0x0010, "OW",
        std::string(reinterpret_cast<const char*>(slices[k].data()), slices[k].size() * 2));

    std::ofstream out(folder / ("slice" + std::to_string(k + 1) + ".dcm"), std::ios::binary);
    out << std::string(128, '\0') << "DICM" << group_length.bytes() << meta_bytes << data.bytes();
  }
}

}  // namespace naris::testing
