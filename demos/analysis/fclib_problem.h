#pragma once
// A captured solve (cps/step_system.h) as a local frictional contact problem of FCLIB (Acary,
// Brémond, Koziniec, Mons, Dubois, Renouf, "FCLIB: a collection of discrete 3D frictional
// contact problems", JOTA 2014), written through Debian's libfclib (HDF5). cps is not linked
// against libfclib: load_fclib opens it (dlopen) when a file is to be written, so that other
// runs do not load it and its libraries (docs/benchmarks.md).
//
// FCLIB's local problem: find r and u (m entries each) and l (p entries) with
//   u = W r + V l + q,   V^T r + R l + s = 0,   Coulomb's cone per contact (n, t1, t2 rows).
// The paper's system (Eq. 6.2.9) is A lambda = b with w = A lambda - b, where dt w is each row's
// velocity after the step beyond its target (m/s). Multiplying by dt:
//   dt w = A (dt lambda) - dt b,
// so with r = dt lambda (the impulse, N s) the velocities u = dt w (m/s) are u = W r + q with
//   W = A_CC (contacts: the contact row, then its two friction rows), 1/kg = (m/s) / (N s),
//   q = -dt b_C (m/s),
//   V = A_CD, R = A_DD (the rods' rows D), s = -dt b_D (m/s): a rod's row is w_D = 0.
// mu per contact is the friction rows' coefficient. A contact without friction rows (friction
// 0) gets two inert tangent rows: W_tt = A_nn, no coupling, q_t = 0, mu = 0, so r_t = 0.
//
// What differs: cps bounds each friction row on its own, a box (fixed: +-mu m g.n, the default;
// coupled: +-mu lambda_n), where FCLIB's law is Coulomb's disc |r_T| <= mu r_N with the
// De Saxcé normal velocity. W, q, V, R, s are cps's own; the friction law is FCLIB's, so an
// FCLIB solver solves Coulomb's problem on cps's dynamics, not cps's box problem
// (docs/exact_reference.md, "FCLIB export").

#include "cps/step_system.h"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <filesystem>
#include <string>
#include <vector>

namespace cps::analysis {

/// A local FCLIB problem (spacedim 3) in cps's numbers; see the file comment for the mapping.
struct FclibLocal {
  /// m x m (m = 3 contacts), 1/kg: A on the contact triples (n, t1, t2), symmetric PSD.
  Eigen::SparseMatrix<double> W;
  /// m x p, 1/kg: A between the contact triples and the rods' rows (p = rods); empty if p = 0.
  Eigen::SparseMatrix<double> V;
  /// p x p, 1/kg: A on the rods' rows; empty if p = 0.
  Eigen::SparseMatrix<double> R;
  Eigen::VectorXd q;   ///< m, m/s: -dt b on the contact triples
  Eigen::VectorXd s;   ///< p, m/s: -dt b on the rods' rows
  Eigen::VectorXd mu;  ///< m / 3, dimensionless: friction coefficient per contact
  /// m: the cps row of each local row (contact row, its first then second friction row), -1 for
  /// an inert tangent row (a contact without friction rows).
  std::vector<int> local_rows;
  /// p: the cps row of each rod row, in cps's order.
  std::vector<int> rod_rows;
  /// The number of contacts (m / 3).
  int contacts() const { return static_cast<int>(mu.size()); }
};

/// The local problem of s (see the file comment). Throws std::invalid_argument when s has no
/// contact row (FCLIB's local problem needs one), when a contact has a number of friction rows
/// other than 0 or 2, or when the sizes of s disagree.
FclibLocal fclib_local_problem(const StepSystem& s);

/// The text FCLIB keeps beside a problem (fclib_info): title, description, math_info.
struct FclibText {
  std::string title;
  std::string description;
  std::string math_info;
};

/// The mapping of the file comment in a few lines, with units, for FclibText::math_info.
std::string fclib_mapping_text();

/// Opens FCLIB's shared library, once per process: the name in the environment variable
/// CPS_FCLIB_LIBRARY if set and not empty, else the SONAME found when cps was configured
/// (CMake's CPS_FCLIB_SONAME, e.g. libfclib.so.0, Debian's libfclib0), searched as dlopen(3)
/// searches; then resolves the functions cps calls (fclib_write_local). Returns the name opened.
/// Throws std::runtime_error naming the library and the Debian packages (libfclib0,
/// libfclib-dev) when it cannot be opened or lacks a function; a later call tries again.
std::string load_fclib();

/// Writes p and its text as a new FCLIB file at `path` (fclib_write_local: the group
/// /fclib_local; W, V, R in compressed columns). `path` must not exist (fclib would add to an
/// HDF5 file already there). Opens FCLIB first (load_fclib). Throws std::invalid_argument when
/// p's sizes disagree or exceed FCLIB's int indices, std::runtime_error when FCLIB cannot be
/// opened (load_fclib), or naming the path and the reason when the write fails. FCLIB ends its
/// process (exit) on a failed HDF5 call, so the write runs in a child process (fork(2)): its
/// failure, exit or signal, becomes the exception, with the first line it printed; the caller
/// removes what the child left at `path`.
void write_fclib_local(const FclibLocal& p, const FclibText& text, const std::filesystem::path& path);

}  // namespace cps::analysis
