#pragma once
// Output-error models of olfactory responses (dissertation ch. 5, eq. 5.3):
//   y_df(k) = −Σ_{j=1..na} a_j y_df(k−j) + Σ_{j=1..nb} b_j u(k − nd − j + 1),   y = y_df + e.
#include <complex>
#include <string>
#include <vector>

namespace naris::olfaction {

struct OeModel {
  std::string name;
  std::vector<double> a;          // a_1 .. a_na (A(q) = 1 + a_1 q⁻¹ + … + a_na q^−na)
  std::vector<double> b;          // b_1 .. b_nb
  int nd = 1;                     // input delay in samples
  double sample_rate = 200.0;     // Hz
  std::string input_unit = "mM";  // b_j are per input unit (mM⁻¹ or µM⁻¹)
  std::string output_unit = "a.u.";

  int na() const { return static_cast<int>(a.size()); }
  int nb() const { return static_cast<int>(b.size()); }
};

// Roots of z^na + a_1 z^(na−1) + … + a_na: the model's poles.
std::vector<std::complex<double>> poles(const OeModel& m);
// The largest pole magnitude (0 for na = 0).
double spectral_radius(const OeModel& m);
bool is_stable(const OeModel& m);

// Throws naris::Error naming the model and the offending pole unless every pole lies strictly
// inside the unit circle.
void require_stable(const OeModel& m);

// The same model with each pole outside the unit circle reflected to 1/z̄ (the magnitude
// response keeps its shape; the phase changes), A rescaled to stay monic.
OeModel stabilized(const OeModel& m);

// The disturbance-free output y_df for input u (same length; u before k = 0 is zero).
std::vector<double> simulate(const OeModel& m, const std::vector<double>& u);

// The three models of Table 5.1, as printed (four significant digits), sampled at 200 Hz.
OeModel rat_single_cell();  // na = 5, nb = 1, nd = 52, b in mM⁻¹
OeModel rat_eog();          // na = 8, nb = 2, nd = 50, b in µM⁻¹
OeModel dog_eog();          // na = 9, nb = 4, nd = 11, b in µM⁻¹
std::vector<OeModel> presets();
// A preset by name ("rat-single-cell", "rat-eog", "dog-eog"); throws naris::Error otherwise.
OeModel preset(const std::string& name);

}  // namespace naris::olfaction
