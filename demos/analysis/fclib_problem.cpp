// A captured solve as a local FCLIB problem (see fclib_problem.h).
#include "fclib_problem.h"

#include "shared_library.h"

// fclib.h declares C functions without extern "C". Only its types and declarations are used:
// the functions are resolved in the library opened by load_fclib.
extern "C" {
#include <fclib.h>
}

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <csignal>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

namespace cps::analysis {
namespace {

// The submatrix of A (rows `rows`, columns `cols`; -1 picks nothing: an inert row or column),
// plus `diagonal` on the diagonal entries of inert rows (square blocks only).
Eigen::SparseMatrix<double> block(const Eigen::SparseMatrix<double, Eigen::RowMajor>& A,
                                  const std::vector<int>& rows, const std::vector<int>& cols,
                                  const Eigen::VectorXd* inert_diagonal) {
  std::vector<int> col_of(static_cast<std::size_t>(A.cols()), -1);
  for (std::size_t k = 0; k < cols.size(); ++k) {
    if (cols[k] >= 0) col_of[static_cast<std::size_t>(cols[k])] = static_cast<int>(k);
  }
  std::vector<Eigen::Triplet<double>> entries;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (rows[i] < 0) {
      if (inert_diagonal != nullptr) {
        entries.emplace_back(static_cast<int>(i), static_cast<int>(i), (*inert_diagonal)[static_cast<Eigen::Index>(i)]);
      }
      continue;
    }
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(A, rows[i]); it; ++it) {
      const int k = col_of[static_cast<std::size_t>(it.col())];
      if (k >= 0) entries.emplace_back(static_cast<int>(i), k, it.value());
    }
  }
  Eigen::SparseMatrix<double> out(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(cols.size()));
  out.setFromTriplets(entries.begin(), entries.end());
  out.makeCompressed();
  return out;
}

// An fclib_matrix (compressed columns, nz = -1) that points into m's arrays: valid while m lives.
fclib_matrix view(Eigen::SparseMatrix<double>& m) {
  m.makeCompressed();
  fclib_matrix f{};
  f.nzmax = static_cast<int>(m.nonZeros());
  f.m = static_cast<int>(m.rows());
  f.n = static_cast<int>(m.cols());
  f.p = m.outerIndexPtr();
  f.i = m.innerIndexPtr();
  f.x = m.valuePtr();
  f.nz = -1;
  f.info = nullptr;
  return f;
}

// FCLIB's functions cps calls, resolved in its library (load_fclib).
struct FclibFunctions {
  std::string library;
  decltype(&fclib_write_local) write_local = nullptr;
};

FclibFunctions open_fclib() {
  const std::string what = "FCLIB's library";
  const std::string hint = "; cps export --fclib needs it: install Debian's libfclib0 "
                           "(libfclib-dev to build cps with FCLIB)";
  // Kept open to the end of the process (HDF5 holds global state).
  const detail::SharedLibrary lib =
      detail::open_shared_library("CPS_FCLIB_LIBRARY", CPS_FCLIB_SONAME, what, hint);
  FclibFunctions f;
  f.library = lib.file;
  detail::resolve_symbol(lib, "fclib_write_local", what, hint, f.write_local);
  return f;
}

const FclibFunctions& fclib_functions() {
  // Initialised once, thread-safe; an exception leaves it for the next call to try again.
  static const FclibFunctions functions = open_fclib();
  return functions;
}

}  // namespace

std::string load_fclib() { return fclib_functions().library; }

FclibLocal fclib_local_problem(const StepSystem& s) {
  const Eigen::Index c = s.rows();
  if (s.A.rows() != c || s.A.cols() != c || static_cast<Eigen::Index>(s.kinds.size()) != c ||
      static_cast<Eigen::Index>(s.normal_row.size()) != c || s.mu.size() != c) {
    throw std::invalid_argument("fclib_local_problem: the system's sizes disagree");
  }
  // Each contact row's friction rows, in cps's order (the first is t1, the second t2).
  std::vector<std::vector<int>> friction_of(static_cast<std::size_t>(c));
  for (Eigen::Index j = 0; j < c; ++j) {
    if (s.kinds[static_cast<std::size_t>(j)] != RowKind::friction) continue;
    const int n = s.normal_row[static_cast<std::size_t>(j)];
    if (n < 0 || n >= c || s.kinds[static_cast<std::size_t>(n)] != RowKind::contact) {
      throw std::invalid_argument("fclib_local_problem: friction row " + std::to_string(j) +
                                  " has no contact row");
    }
    friction_of[static_cast<std::size_t>(n)].push_back(static_cast<int>(j));
  }
  FclibLocal p;
  std::vector<double> mu;
  std::vector<double> inert;  // the diagonal of each local row (used by inert rows only)
  for (Eigen::Index j = 0; j < c; ++j) {
    const RowKind kind = s.kinds[static_cast<std::size_t>(j)];
    if (kind == RowKind::distance) p.rod_rows.push_back(static_cast<int>(j));
    if (kind != RowKind::contact) continue;
    const std::vector<int>& t = friction_of[static_cast<std::size_t>(j)];
    if (t.size() != 0 && t.size() != 2) {
      throw std::invalid_argument("fclib_local_problem: contact row " + std::to_string(j) + " has " +
                                  std::to_string(t.size()) + " friction rows (FCLIB's 3D contact "
                                  "needs 2 tangents, or none for a frictionless one)");
    }
    const double a_nn = s.A.coeff(j, j);
    p.local_rows.push_back(static_cast<int>(j));
    p.local_rows.push_back(t.empty() ? -1 : t[0]);
    p.local_rows.push_back(t.empty() ? -1 : t[1]);
    inert.insert(inert.end(), {a_nn, a_nn, a_nn});
    mu.push_back(t.empty() ? 0.0 : s.mu[t[0]]);
  }
  if (mu.empty()) {
    throw std::invalid_argument("the solve has no contact row (" + std::to_string(c) +
                                " rows, all rods): FCLIB's local problem needs at least one contact");
  }
  const Eigen::VectorXd diagonal = Eigen::Map<const Eigen::VectorXd>(inert.data(), static_cast<Eigen::Index>(inert.size()));
  p.W = block(s.A, p.local_rows, p.local_rows, &diagonal);
  p.q.resize(static_cast<Eigen::Index>(p.local_rows.size()));
  for (std::size_t i = 0; i < p.local_rows.size(); ++i) {
    const int j = p.local_rows[i];
    p.q[static_cast<Eigen::Index>(i)] = j < 0 ? 0.0 : -s.dt * s.b[j];
  }
  p.mu = Eigen::Map<const Eigen::VectorXd>(mu.data(), static_cast<Eigen::Index>(mu.size()));
  if (!p.rod_rows.empty()) {
    p.V = block(s.A, p.local_rows, p.rod_rows, nullptr);
    p.R = block(s.A, p.rod_rows, p.rod_rows, nullptr);
    p.s.resize(static_cast<Eigen::Index>(p.rod_rows.size()));
    for (std::size_t i = 0; i < p.rod_rows.size(); ++i) {
      p.s[static_cast<Eigen::Index>(i)] = -s.dt * s.b[p.rod_rows[i]];
    }
  }
  return p;
}

std::string fclib_mapping_text() {
  return "cps (Tamis & Maggiore 2015, Eq. 6.2.9) solves A lambda = b, A = J M^-1 J^T (1/kg), "
         "b (m/s^2), lambda (N), w = A lambda - b, with per-row bounds. Here r = dt lambda (N s), "
         "u = dt w (m/s: a row's velocity after the step beyond its target). Contacts: rows "
         "(n, t1, t2) = (contact row, its two friction rows); W = A on them (1/kg), q = -dt b "
         "(m/s). Rods (bilateral rows D): V = A_CD, R = A_DD (1/kg), s = -dt b_D (m/s), l = dt "
         "lambda_D (N s). mu: the friction rows' coefficient; a frictionless contact has inert "
         "tangents (W_tt = A_nn, q_t = 0, mu = 0). W is symmetric positive semi-definite. cps's "
         "friction is a box per tangent row (fixed limits +-mu m g.n by default, or +-mu "
         "lambda_n), FCLIB's is Coulomb's cone: this file is Coulomb's problem on cps's W and q, "
         "not cps's box problem.";
}

namespace {

// The reason in HDF5's diagnostics (its error stack, as fclib's child printed it): the system's
// message of the failed call ("No space left on device") where HDF5 gives one, else the last
// "minor:" line; "" when there is neither.
std::string hdf5_reason(const std::string& said) {
  const std::string key = "error message = '";
  const std::size_t at = said.rfind(key);
  if (at != std::string::npos) {
    const std::size_t end = said.find('\'', at + key.size());
    if (end != std::string::npos) return ": " + said.substr(at + key.size(), std::min<std::size_t>(end - at - key.size(), 200));
  }
  const std::size_t minor = said.rfind("minor: ");
  if (minor == std::string::npos) return "";
  const std::size_t end = said.find('\n', minor);
  return ": HDF5 says " + said.substr(minor + 7, std::min<std::size_t>(end == std::string::npos ? said.size() - minor - 7 : end - minor - 7, 200));
}

}  // namespace

void write_fclib_local(const FclibLocal& p, const FclibText& text, const std::filesystem::path& path) {
  const Eigen::Index m = p.W.rows();
  const Eigen::Index rods = static_cast<Eigen::Index>(p.rod_rows.size());
  if (p.W.cols() != m || m != 3 * p.mu.size() || p.q.size() != m || p.s.size() != rods ||
      (rods > 0 && (p.V.rows() != m || p.V.cols() != rods || p.R.rows() != rods || p.R.cols() != rods))) {
    throw std::invalid_argument("write_fclib_local: the problem's sizes disagree");
  }
  if (p.W.nonZeros() > INT_MAX || p.V.nonZeros() > INT_MAX || m > INT_MAX) {
    throw std::invalid_argument("write_fclib_local: more entries than FCLIB's int indices hold");
  }
  const FclibFunctions& fclib = fclib_functions();
  std::error_code ec;
  if (std::filesystem::exists(std::filesystem::symlink_status(path, ec))) {
    throw std::invalid_argument("write_fclib_local: " + path.string() + " exists (fclib would add to it)");
  }
  // fclib takes non-const pointers; it only reads them when writing.
  FclibLocal copy = p;
  std::string title = text.title;
  std::string description = text.description;
  std::string math_info = text.math_info;
  fclib_info info{title.data(), description.data(), math_info.data()};
  fclib_matrix W = view(copy.W);
  fclib_matrix V{};
  fclib_matrix R{};
  fclib_local problem{};
  problem.W = &W;
  problem.mu = copy.mu.data();
  problem.q = copy.q.data();
  problem.spacedim = 3;
  problem.info = &info;
  if (rods > 0) {
    V = view(copy.V);
    R = view(copy.R);
    problem.V = &V;
    problem.R = &R;
    problem.s = copy.s.data();
  }
  // fclib ends the process (exit) when an HDF5 call fails, as on a full disk: the write runs in a
  // child process, whose end and stderr (HDF5's diagnostics) this process reads.
  int pipe_fds[2];
  if (::pipe(pipe_fds) != 0) {
    throw std::runtime_error("cannot write " + path.string() + ": pipe: " + std::strerror(errno));
  }
  const pid_t child = ::fork();
  if (child < 0) {
    const int error = errno;
    ::close(pipe_fds[0]);
    ::close(pipe_fds[1]);
    throw std::runtime_error("cannot write " + path.string() + ": fork: " + std::strerror(error));
  }
  if (child == 0) {
    ::close(pipe_fds[0]);
    ::dup2(pipe_fds[1], STDERR_FILENO);
    ::dup2(pipe_fds[1], STDOUT_FILENO);
    ::_exit(fclib.write_local(&problem, path.c_str()) == 1 ? 0 : 1);
  }
  ::close(pipe_fds[1]);
  std::string said;  // the first 4 KiB the child printed
  char chunk[4096];
  for (;;) {
    const ssize_t n = ::read(pipe_fds[0], chunk, sizeof chunk);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    if (said.size() < sizeof chunk) said.append(chunk, static_cast<std::size_t>(n));
  }
  ::close(pipe_fds[0]);
  int status = 0;
  while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return;
  std::string why = WIFSIGNALED(status) ? "fclib_write_local was ended by signal " +
                                              std::to_string(WTERMSIG(status)) + " (" +
                                              strsignal(WTERMSIG(status)) + ")"
                                        : "fclib_write_local failed (exit " +
                                              std::to_string(WEXITSTATUS(status)) + ")";
  why += hdf5_reason(said);
  throw std::runtime_error("cannot write " + path.string() + ": " + why);
}

}  // namespace cps::analysis
