#pragma once
// The nasal airway of a clinical head CT, found automatically (docs/method/nasal-airway.md):
// the room air is cut off at the nares, the paranasal sinuses are left out behind their ostia,
// and one side is separated from the other by the septum down to the choana. What it returns
// is the labelmap and the cut planes the mesher needs (the naris as the inlet, the choana or
// the nasopharynx as the outlet).
#include <Eigen/Dense>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "mesh/image/volume.h"

namespace naris {

enum class NasalSide { right, left, both };
NasalSide parse_nasal_side(const std::string& text);
const char* nasal_side_name(NasalSide side);

struct NasalAirwayOptions {
  // HU; absent: automatic, half-way from the histogram's air–tissue valley (air_threshold) to
  // water, with the wall drawn 60 % of the way (NasalAirway::wall_level).
  std::optional<double> threshold;
  NasalSide side = NasalSide::right;
  // The nasopharynx behind the choana: kept whole, or cut (one side ends at its choana; both
  // sides end a little behind the choanae, where they have joined).
  bool keep_nasopharynx = false;
  double closing_radius = 5.0;   // mm: balls of this radius do not pass through a nostril
  double sinus_margin = 2.5;     // mm: how much wider than its way in a cavity is to be a sinus
  double ethmoid_height = 25.0;  // mm above the nares: the ethmoid labyrinth, where ...
  double ethmoid_margin = 0.5;   // mm: ... any narrowing on the way in makes a sinus
  int threads = 0;
};

// One naris: where the vestibule's air meets the room air.
struct Naris {
  bool right = false;  // the patient's right
  double area = 0.0;   // mm², of the voxel faces shared with the room air
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit, towards the room
};

// What each voxel of the scan became (NasalAirway::regions), for checking in 3D Slicer.
enum class AirwayRegion : std::uint8_t {
  tissue = 0,
  airway = 1,    // the result
  sinus = 2,     // reached from the nares, left out behind an ostium
  room = 3,      // outside the body
  excluded = 4,  // nasal air not kept: the other side, behind the choana, the scan's border
  enclosed = 5,  // air inside the body not reached from the nares
  masked = 6,    // a de-identification mask, taken for tissue
};

struct NasalAirway {
  Volume<std::uint8_t> mask;     // 1: the airway
  Volume<std::uint8_t> regions;  // AirwayRegion per voxel
  double threshold = 0.0;
  double wall_level = 0.0;     // HU: the wall's partial-volume layer lies between it and threshold
  double wall_layer_ml = 0.0;  // of the airway, the wall's layer added at wall_level
  std::vector<Naris> nares;    // those the airway is entered by (one, or both)
  std::string inlet;           // cut plane p=…;n=… (mm) across the nares
  std::string outlet;          // cut plane: the choana, or the nasopharynx's cut (or none)
  std::optional<int> choana;   // the last slice before the sides join, along the A-P axis
  int ap_axis = 1;             // the image axis closest to anterior–posterior
  double volume_ml = 0.0;
  double sinus_ml = 0.0;          // air reached from the nares and left out as sinus
  double room_ml = 0.0;           // room air (outside the body)
  std::size_t sinuses = 0;        // cavities left out
  std::size_t masked_voxels = 0;  // de-identification masks taken for tissue
};

// Throws naris::Error, with a message for a person, when the CT has no air inside the body,
// no naris is found, the requested side has no naris, or the sides cannot be separated.
NasalAirway segment_nasal_airway(const Volume<float>& ct, const NasalAirwayOptions& options);

}  // namespace naris
