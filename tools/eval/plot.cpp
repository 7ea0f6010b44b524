#include "tools/eval/plot.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <vector>

#include "tools/eval/eval_error.hpp"

extern char** environ;

namespace posed::eval {
namespace {

namespace fs = std::filesystem;

/// plot-eval's exit code when matplotlib (or numpy) cannot be imported: try another python.
constexpr int kScriptMissingMatplotlib = 3;

const char* alignment_title(Alignment a) {
  switch (a) {
    case Alignment::kNone:
      return "not aligned";
    case Alignment::kSE3:
      return "SE(3) aligned";
    case Alignment::kSim3:
      return "Sim(3) aligned";
  }
  return "";
}

/// Runs argv (argv[0] looked up on PATH); the exit code, or -1 with errno text in `error`.
int run_process(const std::vector<std::string>& args, std::string& error) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, argv[0], nullptr, nullptr, argv.data(), environ);
  if (rc != 0) {
    error = std::string(std::strerror(rc));
    return -1;
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) {
      error = std::string("waitpid: ") + std::strerror(errno);
      return -1;
    }
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  error = "killed by signal " + std::to_string(WTERMSIG(status));
  return -1;
}

}  // namespace

void write_plot_csv(const EvalResult& r, const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) throw EvalError(path + ": cannot write: " + std::strerror(errno));
  std::fprintf(f, "gt_x_m,gt_y_m,gt_z_m,est_x_m,est_y_m,est_z_m,ate_m\n");
  for (std::size_t k = 0; k < r.p_gt_m.size(); ++k) {
    const auto& g = r.p_gt_m[k];
    const auto& e = r.p_est_aligned_m[k];
    std::fprintf(f, "%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", g.x(), g.y(), g.z(), e.x(), e.y(),
                 e.z(), r.ate_errors_m[k]);
  }
  const bool failed = std::ferror(f) != 0;
  if (std::fclose(f) != 0 || failed) throw EvalError(path + ": write error");
}

std::string find_plot_script() {
  std::vector<fs::path> candidates;
  if (const char* src = std::getenv("POSED_SOURCE_DIR"); src != nullptr && *src != '\0') {
    candidates.push_back(fs::path(src) / "tools" / "plot-eval");
  }
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    candidates.push_back(exe.parent_path() / ".." / "share" / "posed" / "plot-eval");
    candidates.push_back(exe.parent_path() / "plot-eval");
  }
#ifdef POSED_EVAL_SOURCE_DIR
  candidates.push_back(fs::path(POSED_EVAL_SOURCE_DIR) / "tools" / "plot-eval");
#endif
  for (const auto& c : candidates) {
    if (fs::is_regular_file(c, ec)) return fs::weakly_canonical(c, ec).string();
  }
  return {};
}

PlotOutcome plot_evaluation(const EvalResult& result, const std::string& out_png,
                            const std::string& label) {
  PlotOutcome out;
  const std::string script = find_plot_script();
  if (script.empty()) {
    out.message =
        "tools/plot-eval not found (set POSED_SOURCE_DIR to the posed source tree, or install "
        "posed so that share/posed/plot-eval sits beside bin/)";
    return out;
  }
  std::vector<std::string> pythons;
  if (const char* py = std::getenv("POSED_PYTHON"); py != nullptr && *py != '\0') {
    pythons.emplace_back(py);
  } else {
    if (::access("/usr/bin/python3", X_OK) == 0) pythons.emplace_back("/usr/bin/python3");
    pythons.emplace_back("python3");
  }

  const fs::path tmp_dir = fs::temp_directory_path();
  std::string csv_template = (tmp_dir / "posectl-eval-XXXXXX.csv").string();
  const int fd = ::mkstemps(csv_template.data(), 4);
  if (fd < 0) {
    out.message =
        "cannot create a temporary file in " + tmp_dir.string() + ": " + std::strerror(errno);
    return out;
  }
  ::close(fd);
  const std::string csv_path = csv_template;
  try {
    write_plot_csv(result, csv_path);
  } catch (const EvalError& e) {
    std::remove(csv_path.c_str());
    out.message = e.what();
    return out;
  }

  std::string tried;
  for (const std::string& python : pythons) {
    std::string error;
    const int rc = run_process({python, script, csv_path, out_png, "--label", label, "--alignment",
                                alignment_title(result.alignment)},
                               error);
    if (rc == 0) {
      out.written = true;
      break;
    }
    tried += (tried.empty() ? "" : ", ") + python;
    if (rc == -1) {
      out.message = "cannot run " + python + ": " + error;
      continue;  // no such interpreter: the next may exist
    }
    if (rc == kScriptMissingMatplotlib) {
      out.message = "no python3 with matplotlib found (tried " + tried +
                    "); install python3-matplotlib (tools/install-deps)";
      continue;
    }
    out.message = script + " failed with exit code " + std::to_string(rc);
    break;  // the script ran and failed on its own terms: another python will not help
  }
  std::remove(csv_path.c_str());
  if (out.written) out.message.clear();
  return out;
}

}  // namespace posed::eval
