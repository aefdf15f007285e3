#include "mesh/image/read_volume.h"

#include <gdcmDirectory.h>
#include <gdcmIPPSorter.h>
#include <gdcmScanner.h>
#include <gdcmTrace.h>
#include <vtkCallbackCommand.h>
#include <vtkDataArray.h>
#include <vtkExecutive.h>
#include <vtkGDCMImageReader.h>
#include <vtkImageData.h>
#include <vtkImageReader2.h>
#include <vtkMatrix3x3.h>
#include <vtkMatrix4x4.h>
#include <vtkMetaImageReader.h>
#include <vtkNIFTIImageReader.h>
#include <vtkNrrdReader.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkStringArray.h>
#include <vtkXMLImageDataReader.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <regex>
#include <sstream>

#include "core/error.h"

namespace naris {
namespace fs = std::filesystem;

namespace {

// VTK readers report problems through events rather than exceptions: collect them so that the
// caller gets one clear error instead of messages on the console.
struct ErrorCollector {
  std::string message;
  static void on_error(vtkObject*, unsigned long, void* client, void* call) {
    auto* self = static_cast<ErrorCollector*>(client);
    if (self->message.empty() && call) self->message = static_cast<const char*>(call);
  }
};

std::string lower_extension(const fs::path& path) {
  std::string name = path.filename().string();
  std::transform(name.begin(), name.end(), name.begin(), ::tolower);
  if (name.ends_with(".nii.gz")) return ".nii.gz";
  return fs::path(name).extension().string();
}

std::string first_line(const std::string& s) {
  std::string line = s.substr(0, s.find('\n'));
  while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) line.pop_back();
  return line;
}

// vtkNrrdReader keeps only the lengths of `space directions`; the rotation and `space origin`
// are read here from the header (plain text up to the first blank line).
void read_nrrd_frame(const fs::path& path, ImageFrame& frame) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  const std::regex vec(R"(\(\s*([^,\s]+)\s*,\s*([^,\s]+)\s*,\s*([^,\s\)]+)\s*\))");
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) break;
    auto parse_vectors = [&](const std::string& text) {
      std::vector<Eigen::Vector3d> out;
      for (std::sregex_iterator it(text.begin(), text.end(), vec), end; it != end; ++it)
        out.emplace_back(std::stod((*it)[1]), std::stod((*it)[2]), std::stod((*it)[3]));
      return out;
    };
    if (line.rfind("space directions:", 0) == 0) {
      const auto dirs = parse_vectors(line.substr(17));
      if (dirs.size() != 3) fail("{}: 'space directions' must list three vectors", path.string());
      for (int a = 0; a < 3; ++a) {
        const double len = dirs[a].norm();
        if (!(len > 0.0) || !std::isfinite(len))
          fail("{}: 'space directions' has a zero or non-finite vector", path.string());
        frame.spacing[a] = len;
        frame.direction.col(a) = dirs[a] / len;
      }
    } else if (line.rfind("space origin:", 0) == 0) {
      const auto o = parse_vectors(line.substr(13));
      if (o.size() == 1) frame.origin = o[0];
    }
  }
}

// 3D Slicer's segmentation NRRD names its segments in key:=value lines of the header:
// SegmentN_Name and SegmentN_LabelValue (the label value defaults to N + 1).
std::map<int, std::string> read_nrrd_label_names(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::map<int, std::string> names, values;
  const std::regex field(R"(^Segment(\d+)_(Name|LabelValue):=(.*)$)");
  std::string line;
  std::smatch m;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) break;
    if (!std::regex_match(line, m, field)) continue;
    (m[2] == "Name" ? names : values)[std::stoi(m[1])] = m[3];
  }
  std::map<int, std::string> out;
  for (const auto& [segment, name] : names) {
    int label = segment + 1;
    if (const auto it = values.find(segment); it != values.end()) {
      try {
        label = std::stoi(it->second);
      } catch (const std::exception&) {
        fail("{}: Segment{}_LabelValue '{}' is not a number", path.string(), segment, it->second);
      }
    }
    out[label] = name;
  }
  return out;
}

// vtkNrrdReader does not notice a truncated payload (it hands back what it could read), so the
// payload length is checked here: the inflated size for gzip, the file size for raw data.
void check_nrrd_payload(const fs::path& path, std::size_t expected_bytes) {
  std::ifstream in(path, std::ios::binary);
  std::string line, encoding = "raw";
  bool detached = false;
  std::streamoff data_start = 0;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) {
      data_start = in.tellg();
      break;
    }
    if (line.rfind("encoding:", 0) == 0) {
      encoding = line.substr(9);
      encoding.erase(0, encoding.find_first_not_of(' '));
    }
    if (line.rfind("data file:", 0) == 0 || line.rfind("datafile:", 0) == 0) detached = true;
  }
  if (detached || data_start <= 0) return;
  in.clear();
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (encoding == "raw") {
    if (static_cast<std::size_t>(size - data_start) < expected_bytes)
      fail("{}: truncated file: {} bytes of voxel data, {} expected", path.string(),
           size - data_start, expected_bytes);
    return;
  }
  if (encoding != "gzip" && encoding != "gz") return;
  in.seekg(data_start);
  std::vector<unsigned char> packed(static_cast<std::size_t>(size - data_start));
  in.read(reinterpret_cast<char*>(packed.data()), static_cast<std::streamsize>(packed.size()));
  z_stream z{};
  if (inflateInit2(&z, 16 + MAX_WBITS) != Z_OK) return;
  z.next_in = packed.data();
  z.avail_in = static_cast<uInt>(packed.size());
  std::vector<unsigned char> chunk(1 << 16);
  std::size_t total = 0;
  int rc = Z_OK;
  while (rc == Z_OK) {
    z.next_out = chunk.data();
    z.avail_out = static_cast<uInt>(chunk.size());
    rc = inflate(&z, Z_NO_FLUSH);
    total += chunk.size() - z.avail_out;
  }
  inflateEnd(&z);
  if (rc != Z_STREAM_END || total < expected_bytes)
    fail("{}: truncated or corrupt gzip data: {} of {} bytes could be decompressed", path.string(),
         total, expected_bytes);
}

}  // namespace

Volume<float> read_volume(const fs::path& path, VolumeInfo* info) {
  std::error_code ec;
  if (!fs::exists(path, ec)) fail("{}: no such file or folder", path.string());

  ErrorCollector errors;
  auto cb = vtkSmartPointer<vtkCallbackCommand>::New();
  cb->SetCallback(&ErrorCollector::on_error);
  cb->SetClientData(&errors);
  vtkObject::GlobalWarningDisplayOff();

  VolumeInfo meta;
  vtkSmartPointer<vtkImageData> image;
  const std::string ext = fs::is_directory(path) ? std::string("<dir>") : lower_extension(path);
  ImageFrame frame;
  bool frame_from_header = false;

  auto run = [&](auto reader) {
    reader->AddObserver(vtkCommand::ErrorEvent, cb);
    reader->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, cb);
    reader->Update();
    image = reader->GetOutput();
  };

  if (ext == ".nrrd" || ext == ".nhdr") {
    meta.format = "nrrd";
    auto reader = vtkSmartPointer<vtkNrrdReader>::New();
    reader->SetFileName(path.c_str());
    if (!reader->CanReadFile(path.c_str()))
      fail("{}: not a readable NRRD file (bad magic or header)", path.string());
    run(reader);
    read_nrrd_frame(path, frame);
    meta.label_names = read_nrrd_label_names(path);
    frame_from_header = true;
  } else if (ext == ".nii" || ext == ".nii.gz") {
    meta.format = "nifti";
    auto reader = vtkSmartPointer<vtkNIFTIImageReader>::New();
    reader->SetFileName(path.c_str());
    run(reader);
    if (errors.message.empty() && image) {
      vtkMatrix4x4* m =
          reader->GetSFormMatrix() ? reader->GetSFormMatrix() : reader->GetQFormMatrix();
      if (m) {
        for (int r = 0; r < 3; ++r) {
          for (int c = 0; c < 3; ++c) frame.direction(r, c) = m->GetElement(r, c);
          frame.origin[r] = m->GetElement(r, 3);
        }
        frame_from_header = true;
        const double* sp = image->GetSpacing();
        frame.spacing = Eigen::Vector3d(sp[0], sp[1], sp[2]);
        const double* o = image->GetOrigin();
        frame.origin += frame.direction * Eigen::Vector3d(o[0], o[1], o[2]);
        // NIfTI coordinates are RAS; naris frames are LPS like DICOM and 3D Slicer's NRRD.
        const Eigen::Matrix3d ras_to_lps = Eigen::Vector3d(-1, -1, 1).asDiagonal();
        frame.direction = ras_to_lps * frame.direction;
        frame.origin = ras_to_lps * frame.origin;
      }
    }
  } else if (ext == ".mha" || ext == ".mhd") {
    meta.format = "metaimage";
    auto reader = vtkSmartPointer<vtkMetaImageReader>::New();
    reader->SetFileName(path.c_str());
    if (!reader->CanReadFile(path.c_str()))
      fail("{}: not a readable MetaImage file", path.string());
    run(reader);
  } else if (ext == ".vti") {
    meta.format = "vti";
    auto reader = vtkSmartPointer<vtkXMLImageDataReader>::New();
    reader->SetFileName(path.c_str());
    run(reader);
  } else if (ext == "<dir>") {
    // A DICOM series: GDCM orders the files by their position along the slice normal and
    // measures the spacing between them; the frame comes from the first slice's Image Position
    // and the Image Orientation, with rows kept in file order.
    meta.format = "dicom";
    gdcm::Trace::SetWarning(false);
    gdcm::Trace::SetDebug(false);
    gdcm::Trace::SetError(false);
    gdcm::Directory folder;
    folder.Load(path.string(), false);
    const std::vector<std::string> files = folder.GetFilenames();
    if (files.empty()) fail("{}: the folder holds no files", path.string());
    if (files.size() < 2)
      fail("{}: the series has a single slice; a volume needs at least two", path.string());
    gdcm::IPPSorter sorter;
    sorter.SetComputeZSpacing(true);
    sorter.SetZSpacingTolerance(1e-3);
    if (!sorter.Sort(files))
      fail(
          "{}: cannot order the slices by position (files that are not DICOM, missing Image "
          "Position/Orientation, or slices of different orientation)",
          path.string());
    const double dz = sorter.GetZSpacing();
    if (!(dz > 0.0))
      fail(
          "{}: the slices are not evenly spaced; resample the series to a uniform spacing "
          "before meshing",
          path.string());
    // Every slice must have the same size: GDCM's VTK reader does not check (it crashes).
    gdcm::Scanner scanner;
    const gdcm::Tag rows_tag(0x0028, 0x0010), columns_tag(0x0028, 0x0011);
    scanner.AddTag(rows_tag);
    scanner.AddTag(columns_tag);
    if (!scanner.Scan(sorter.GetFilenames()))
      fail("{}: cannot read the slices' image size", path.string());
    std::string first_size;
    for (const auto& f : sorter.GetFilenames()) {
      const char* r = scanner.GetValue(f.c_str(), rows_tag);
      const char* c = scanner.GetValue(f.c_str(), columns_tag);
      if (!r || !c) fail("{}: slice {} has no Rows/Columns", path.string(), f);
      const std::string size = fmt::format("{}×{}", c, r);
      if (first_size.empty())
        first_size = size;
      else if (size != first_size)
        fail(
            "{}: slices of unequal size in the series ({} and {} in {}); a volume needs equal "
            "slices",
            path.string(), first_size, size, fs::path(f).filename().string());
    }
    auto names = vtkSmartPointer<vtkStringArray>::New();
    for (const auto& f : sorter.GetFilenames()) names->InsertNextValue(f);
    auto reader = vtkSmartPointer<vtkGDCMImageReader>::New();
    reader->SetFileNames(names);
    reader->FileLowerLeftOn();
    run(reader);
    if (errors.message.empty() && image) {
      const double* iop = reader->GetImageOrientationPatient();
      const Eigen::Vector3d row(iop[0], iop[1], iop[2]), col(iop[3], iop[4], iop[5]);
      frame.direction.col(0) = row.normalized();
      frame.direction.col(1) = col.normalized();
      frame.direction.col(2) = row.cross(col).normalized();
      const double* ipp = reader->GetImagePositionPatient();
      frame.origin = Eigen::Vector3d(ipp[0], ipp[1], ipp[2]);
      const double* sp = image->GetSpacing();
      frame.spacing = Eigen::Vector3d(sp[0], sp[1], dz);
      frame_from_header = true;
    }
  } else {
    fail(
        "{}: unknown image format '{}' (expected .nrrd, .nhdr, .nii, .nii.gz, .mha, .mhd, "
        ".vti or a DICOM folder)",
        path.string(), ext);
  }

  if (!errors.message.empty())
    fail("{}: cannot read {} data: {}", path.string(), meta.format, first_line(errors.message));
  if (!image || !image->GetPointData() || !image->GetPointData()->GetScalars())
    fail("{}: the file holds no image data (missing, truncated or corrupt)", path.string());

  vtkDataArray* scalars = image->GetPointData()->GetScalars();
  meta.pixel_type = scalars->GetDataTypeAsString();
  if (scalars->GetNumberOfComponents() != 1)
    fail("{}: unsupported pixel type: {} components per voxel (need a scalar image)", path.string(),
         scalars->GetNumberOfComponents());

  int dims[3];
  image->GetDimensions(dims);
  if (dims[0] < 2 || dims[1] < 2 || dims[2] < 2)
    fail(
        "{}: the image is {}×{}×{}; a volume needs at least two voxels along each axis "
        "(a single slice is not a volume)",
        path.string(), dims[0], dims[1], dims[2]);

  Volume<float> volume;
  if (!frame_from_header) {
    const double* sp = image->GetSpacing();
    const double* o = image->GetOrigin();
    frame.spacing = Eigen::Vector3d(sp[0], sp[1], sp[2]);
    frame.origin = Eigen::Vector3d(o[0], o[1], o[2]);
    if (vtkMatrix3x3* d = image->GetDirectionMatrix())
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) frame.direction(r, c) = d->GetElement(r, c);
  }
  frame.dims = {dims[0], dims[1], dims[2]};
  volume.frame = frame;

  const vtkIdType n = scalars->GetNumberOfTuples();
  if (meta.format == "nrrd")
    check_nrrd_payload(
        path, static_cast<std::size_t>(n) * static_cast<std::size_t>(scalars->GetDataTypeSize()));
  if (static_cast<std::size_t>(n) != frame.voxel_count())
    fail("{}: the data holds {} voxels but the header promises {} (truncated file?)", path.string(),
         n, frame.voxel_count());
  volume.values.resize(static_cast<std::size_t>(n));
  double lo = INFINITY, hi = -INFINITY;
  std::size_t non_finite = 0;
  for (vtkIdType t = 0; t < n; ++t) {
    const double v = scalars->GetTuple1(t);
    if (!std::isfinite(v)) {
      ++non_finite;
      continue;
    }
    lo = std::min(lo, v);
    hi = std::max(hi, v);
    volume.values[static_cast<std::size_t>(t)] = static_cast<float>(v);
  }
  if (non_finite)
    fail("{}: {} voxels hold NaN or infinite values; fix or mask them before meshing",
         path.string(), non_finite);
  meta.min_value = lo;
  meta.max_value = hi;
  if (info) *info = meta;
  return volume;
}

}  // namespace naris
