#include <gtest/gtest.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkMetaImageWriter.h>
#include <vtkNIFTIImageWriter.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkXMLImageDataWriter.h>
#include <zlib.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "mesh/image/read_volume.h"
#include "tests/mesh/image/dicom_writer.h"

namespace naris {
namespace {

namespace fs = std::filesystem;
const fs::path kNeonate = fs::path(NARIS_SHARED_DATA) / "neonate-a.nrrd";

TEST(ReadVolume, ReadsTheNeonateSegmentationWithItsFrame) {
  if (!fs::exists(kNeonate)) GTEST_SKIP() << "shared data absent: " << kNeonate;
  VolumeInfo info;
  const Volume<float> v = read_volume(kNeonate, &info);
  EXPECT_EQ(v.dims(), (std::array<int, 3>{47, 321, 136}));
  EXPECT_NEAR(v.frame.spacing[0], 0.75, 0.01);
  EXPECT_NEAR(v.frame.spacing[1], 0.234, 0.001);
  EXPECT_NEAR(v.frame.spacing[2], 0.2345, 0.001);
  EXPECT_NEAR(std::abs(v.frame.direction.determinant()), 1.0, 1e-6);
  EXPECT_EQ(info.pixel_type, "unsigned char");
  EXPECT_EQ(info.min_value, 0.0);
  EXPECT_EQ(info.max_value, 1.0);
  std::size_t airway = 0;
  for (float x : v.values) airway += x == 1.0f;
  // README: one component of 99,390 voxels plus specks; ≈ 4.1 mL of airway.
  EXPECT_GT(airway, 99390u);
  const double voxel_ml = v.frame.spacing.prod() / 1000.0;
  EXPECT_NEAR(static_cast<double>(airway) * voxel_ml, 4.1, 0.2);
}

// A 7×5×4 float image with distinct values, spacing and origin, written by VTK's own writers.
vtkSmartPointer<vtkImageData> sample_image() {
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(7, 5, 4);
  image->SetSpacing(0.5, 0.25, 2.0);
  image->SetOrigin(-3.0, 1.5, 10.0);
  auto values = vtkSmartPointer<vtkFloatArray>::New();
  values->SetNumberOfTuples(7 * 5 * 4);
  for (vtkIdType n = 0; n < 140; ++n) values->SetValue(n, static_cast<float>(n) * 1.5f - 40.0f);
  image->GetPointData()->SetScalars(values);
  return image;
}

void expect_sample(const Volume<float>& v, bool ras = false) {
  EXPECT_EQ(v.dims(), (std::array<int, 3>{7, 5, 4}));
  EXPECT_NEAR(v.frame.spacing[0], 0.5, 1e-6);
  EXPECT_NEAR(v.frame.spacing[1], 0.25, 1e-6);
  EXPECT_NEAR(v.frame.spacing[2], 2.0, 1e-6);
  // A RAS format (NIfTI) comes back in LPS: x and y change sign.
  EXPECT_NEAR(v.frame.origin[0], ras ? 3.0 : -3.0, 1e-6);
  EXPECT_NEAR(v.frame.origin[1], ras ? -1.5 : 1.5, 1e-6);
  EXPECT_NEAR(v.frame.origin[2], 10.0, 1e-6);
  EXPECT_NEAR(v.frame.direction(0, 0), ras ? -1.0 : 1.0, 1e-9);
  for (int n = 0; n < 140; ++n) EXPECT_EQ(v.values[static_cast<std::size_t>(n)], n * 1.5f - 40.0f);
}

template <class Writer>
void round_trip(const char* name, bool ras = false) {
  const fs::path p = fs::temp_directory_path() / name;
  auto writer = vtkSmartPointer<Writer>::New();
  writer->SetInputData(sample_image());
  writer->SetFileName(p.c_str());
  writer->Write();
  VolumeInfo info;
  expect_sample(read_volume(p, &info), ras);
  EXPECT_EQ(info.pixel_type, "float");
  fs::remove(p);
  fs::remove(fs::path(p).replace_extension(".raw"));
}

TEST(ReadVolume, NiftiRoundTrip) {
  round_trip<vtkNIFTIImageWriter>("naris-sample.nii", true);
}
TEST(ReadVolume, MetaImageRoundTrip) {
  round_trip<vtkMetaImageWriter>("naris-sample.mha");
}
TEST(ReadVolume, VtiRoundTrip) {
  round_trip<vtkXMLImageDataWriter>("naris-sample.vti");
}

TEST(ReadVolume, DicomSeriesFolder) {
  const int nx = 6, ny = 5;
  std::vector<std::vector<std::int16_t>> slices(4, std::vector<std::int16_t>(nx * ny));
  for (int k = 0; k < 4; ++k)
    for (int n = 0; n < nx * ny; ++n)
      slices[k][n] =
          static_cast<std::int16_t>(24 + 37 * n + 300 * k);  // stored; HU = stored − 1024
  const fs::path dir = fs::temp_directory_path() / "naris-dicom-series";
  fs::remove_all(dir);
  // Files named so that a name order would be wrong: the positions decide.
  testing::write_dicom_series(dir, nx, ny, slices, 0.4, 0.5, {14.0, 5.0, 11.0, 8.0});
  VolumeInfo info;
  const Volume<float> v = read_volume(dir, &info);
  EXPECT_EQ(info.format, "dicom");
  ASSERT_EQ(v.dims(), (std::array<int, 3>{nx, ny, 4}));
  EXPECT_NEAR(v.frame.spacing[0], 0.4, 1e-6);  // column spacing (along a row)
  EXPECT_NEAR(v.frame.spacing[1], 0.5, 1e-6);  // row spacing
  EXPECT_NEAR(v.frame.spacing[2], 3.0, 1e-6);
  EXPECT_NEAR((v.frame.origin - Eigen::Vector3d(-10, -20, 5)).norm(), 0.0, 1e-6);
  EXPECT_NEAR((v.frame.direction - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-9);
  // Slice k of the volume is the file at z = 5 + 3k, rows in file order, values in HU.
  const int file_of[4] = {1, 3, 2, 0};
  for (int k = 0; k < 4; ++k)
    for (int n = 0; n < nx * ny; ++n)
      ASSERT_EQ(v.slice(k)[n], slices[file_of[k]][n] - 1024.0f) << "slice " << k << " voxel " << n;
  fs::remove_all(dir);
}

TEST(ReadVolume, DicomSeriesWithUnevenSpacingIsRefused) {
  std::vector<std::vector<std::int16_t>> slices(4, std::vector<std::int16_t>(6 * 5, 100));
  const fs::path dir = fs::temp_directory_path() / "naris-dicom-uneven";
  fs::remove_all(dir);
  testing::write_dicom_series(dir, 6, 5, slices, 0.4, 0.4, {0.0, 3.0, 7.0, 10.0});
  try {
    read_volume(dir);
    FAIL() << "an unevenly spaced series was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("not evenly spaced"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

TEST(ReadVolume, DicomSlicesOfUnequalSizeAreRefused) {
  const fs::path dir = fs::temp_directory_path() / "naris-dicom-unequal";
  fs::remove_all(dir);
  std::vector<std::vector<std::int16_t>> a(2, std::vector<std::int16_t>(6 * 5, 100));
  std::vector<std::vector<std::int16_t>> b(2, std::vector<std::int16_t>(8 * 5, 100));
  testing::write_dicom_series(dir / "a", 6, 5, a, 0.4, 0.4, {0.0, 3.0});
  testing::write_dicom_series(dir / "b", 8, 5, b, 0.4, 0.4, {6.0, 9.0});
  for (const auto& sub : {"a", "b"})
    for (const auto& f : fs::directory_iterator(dir / sub))
      fs::rename(f.path(), dir / (std::string(sub) + f.path().filename().string()));
  fs::remove(dir / "a");
  fs::remove(dir / "b");
  EXPECT_THROW(read_volume(dir), Error);
  fs::remove_all(dir);
}

TEST(ReadVolume, MissingFileIsAClearError) {
  try {
    read_volume("/nonexistent/scan.nrrd");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/scan.nrrd"), std::string::npos);
  }
}

// A gzip-encoded NRRD whose compressed payload is cut short: VTK's reader hands back what it
// could inflate without complaint, so naris must notice.
TEST(ReadVolume, TruncatedGzipNrrdIsAClearError) {
  std::string raw(10 * 10 * 10, '\0');
  for (std::size_t n = 0; n < raw.size(); ++n) raw[n] = static_cast<char>((n * 7919) % 251);
  std::string packed(compressBound(raw.size()) + 64, '\0');
  z_stream z{};
  ASSERT_EQ(deflateInit2(&z, 6, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY), Z_OK);
  z.next_in = reinterpret_cast<Bytef*>(raw.data());
  z.avail_in = static_cast<uInt>(raw.size());
  z.next_out = reinterpret_cast<Bytef*>(packed.data());
  z.avail_out = static_cast<uInt>(packed.size());
  ASSERT_EQ(deflate(&z, Z_FINISH), Z_STREAM_END);
  packed.resize(z.total_out);
  deflateEnd(&z);
  const std::string header =
      "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 10 10 10\nencoding: gzip\n\n";
  const fs::path whole = fs::temp_directory_path() / "naris-whole.nrrd";
  const fs::path cut = fs::temp_directory_path() / "naris-truncated.nrrd";
  std::ofstream(whole, std::ios::binary) << header << packed;
  std::ofstream(cut, std::ios::binary) << header << packed.substr(0, packed.size() / 2);
  const Volume<float> v = read_volume(whole);  // the intact file reads
  EXPECT_EQ(v.values[123], static_cast<float>(static_cast<unsigned char>(raw[123])));
  try {
    read_volume(cut);
    FAIL() << "a truncated file was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("naris-truncated.nrrd"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
  }
  fs::remove(whole);
  fs::remove(cut);
}

TEST(ReadVolume, UnknownFormatIsAClearError) {
  const fs::path junk = fs::temp_directory_path() / "naris-junk.xyz";
  std::ofstream(junk) << "not an image";
  EXPECT_THROW(read_volume(junk), Error);
  fs::remove(junk);
}

}  // namespace
}  // namespace naris
