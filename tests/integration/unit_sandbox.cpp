// unit_sandbox UNIT_FILE [KEY=VALUE...] -- PROGRAM [ARGS...]
//
// Runs PROGRAM under the restrictions a systemd unit file's [Service] section puts on it, applied
// the way systemd applies them, so a test can check that posed lives with its unit without systemd
// as PID 1 (a container, CI). Read from the unit:
//   SystemCallFilter=         seccomp allow list, groups expanded by `systemd-analyze
//                             syscall-filter`, entries applied in order as systemd does; a call
//                             outside it kills the process with SIGSYS (systemd's default action)
//   RestrictAddressFamilies=  socket() of another family fails with EAFNOSUPPORT
//   MemoryDenyWriteExecute=   mmap(W|X) and mprotect(X) fail with EPERM
//   CapabilityBoundingSet=    the bounding set is cut to it; the process then runs as an
//                             unprivileged user (65534) with no supplementary groups, as User= does
//   NoNewPrivileges=          PR_SET_NO_NEW_PRIVS
//   LimitRTPRIO=              the resource limit (clamped, with a notice, where the machine's hard
//                             limit is lower and cannot be raised)
//   ProtectProc= ProcSubset=  a private /proc mounted with hidepid= and subset=
// KEY=VALUE arguments override the unit's settings (e.g. LimitRTPRIO=0 for a control run).
// Needs root (mounting /proc, dropping to another user); exits 125 with the reason otherwise.
// Not applied: file-system and device settings (ProtectSystem, DeviceAllow, ...), IP address
// lists (they need systemd's cgroup BPF programs) and RestrictNamespaces.

#include <errno.h>
#include <grp.h>
#include <linux/capability.h>
#include <seccomp.h>
#include <sys/mman.h>
#include <sys/mount.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "unit_sandbox: %s\n", what.c_str());
  std::exit(125);
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  const auto e = s.find_last_not_of(" \t\r");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

std::vector<std::string> words(const std::string& s) {
  std::istringstream in(s);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

/// Every assignment in [Service], in file order (keys repeat: SystemCallFilter=).
std::vector<std::pair<std::string, std::string>> read_service_section(const std::string& path) {
  std::ifstream in(path);
  if (!in) fail("cannot read unit file " + path);
  std::vector<std::pair<std::string, std::string>> settings;
  bool in_service = false;
  for (std::string line; std::getline(in, line);) {
    line = trim(line);
    if (line.empty() || line[0] == '#' || line[0] == ';') continue;
    if (line[0] == '[') {
      in_service = line == "[Service]";
      continue;
    }
    const auto eq = line.find('=');
    if (in_service && eq != std::string::npos) {
      settings.emplace_back(trim(line.substr(0, eq)), trim(line.substr(eq + 1)));
    }
  }
  return settings;
}

/// systemd's system-call groups (@name -> members, which may be groups), from systemd itself.
std::map<std::string, std::vector<std::string>> syscall_groups() {
  FILE* pipe = ::popen("systemd-analyze syscall-filter --no-pager 2>/dev/null", "r");
  if (pipe == nullptr) fail("cannot run systemd-analyze syscall-filter");
  std::map<std::string, std::vector<std::string>> groups;
  std::string group;
  char buffer[256];
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) {
    const std::string line = buffer;
    const std::string item = trim(line.substr(0, line.find('\n')));
    if (item.empty() || item[0] == '#') continue;
    if (line[0] == '@') {
      group = item;
      groups[group];
    } else if (!group.empty()) {
      groups[group].push_back(item);
    }
  }
  ::pclose(pipe);
  if (groups.count("@system-service") == 0) {
    fail("systemd-analyze syscall-filter listed no groups (Debian package 'systemd')");
  }
  return groups;
}

void expand(const std::string& item, const std::map<std::string, std::vector<std::string>>& groups,
            std::set<std::string>& out) {
  if (item[0] != '@') {
    out.insert(item);
    return;
  }
  const auto it = groups.find(item);
  if (it == groups.end()) fail("unknown system-call group " + item);
  for (const auto& member : it->second) expand(member, groups, out);
}

/// SystemCallFilter= lines in order: the first decides allow- or deny-list; later lines add to
/// or (with ~) take from it, as systemd.exec(5) describes.
std::set<std::string> allowed_syscalls(const std::vector<std::string>& filter_lines) {
  const auto groups = syscall_groups();
  std::set<std::string> allowed;
  bool first = true;
  for (std::string line : filter_lines) {
    const bool deny = !line.empty() && line[0] == '~';
    if (deny) line = line.substr(1);
    if (first && deny)
      fail("a deny-list SystemCallFilter is not supported; start with an allow list");
    first = false;
    std::set<std::string> names;
    for (const auto& w : words(line)) expand(w, groups, names);
    for (const auto& n : names) {
      if (deny) {
        allowed.erase(n);
      } else {
        allowed.insert(n);
      }
    }
  }
  return allowed;
}

int address_family(const std::string& name) {
  static const std::map<std::string, int> families = {
      {"AF_UNIX", AF_UNIX},          {"AF_INET", AF_INET}, {"AF_INET6", AF_INET6},
      {"AF_NETLINK", AF_NETLINK},    {"AF_CAN", AF_CAN},   {"AF_PACKET", AF_PACKET},
      {"AF_BLUETOOTH", AF_BLUETOOTH}};
  const auto it = families.find(name);
  if (it == families.end()) fail("unknown address family " + name);
  return it->second;
}

rlim_t limit_value(const std::string& v) {
  if (v == "infinity") return RLIM_INFINITY;
  return static_cast<rlim_t>(std::stoull(v));
}

void load_filter(scmp_filter_ctx ctx, const char* what) {
  const int rc = seccomp_load(ctx);
  seccomp_release(ctx);
  if (rc != 0) fail(std::string("seccomp_load (") + what + "): " + std::strerror(-rc));
}

// Separate filters, as systemd installs them: the kernel runs all of them and the strictest
// action wins, so a conditional EPERM on mmap is not shadowed by mmap's place in the allow list.
void apply_syscall_filter(const std::set<std::string>& allowed) {
  scmp_filter_ctx ctx = seccomp_init(SCMP_ACT_KILL_PROCESS);
  if (ctx == nullptr) fail("seccomp_init failed");
  for (const auto& name : allowed) {
    const int nr = seccomp_syscall_resolve_name(name.c_str());
    if (nr == __NR_SCMP_ERROR || nr < 0) continue;  // not a call on this architecture
    const int rc = seccomp_rule_add(ctx, SCMP_ACT_ALLOW, nr, 0);
    if (rc != 0) fail("seccomp allow " + name + ": " + std::strerror(-rc));
  }
  load_filter(ctx, "SystemCallFilter");
}

void apply_address_families(const std::set<int>& families) {
  scmp_filter_ctx ctx = seccomp_init(SCMP_ACT_ALLOW);
  for (int family = 0; family < AF_MAX; ++family) {
    if (families.count(family) != 0) continue;
    seccomp_rule_add(ctx, SCMP_ACT_ERRNO(EAFNOSUPPORT), SCMP_SYS(socket), 1,
                     SCMP_A0(SCMP_CMP_EQ, static_cast<scmp_datum_t>(family)));
  }
  seccomp_rule_add(ctx, SCMP_ACT_ERRNO(EAFNOSUPPORT), SCMP_SYS(socket), 1,
                   SCMP_A0(SCMP_CMP_GE, static_cast<scmp_datum_t>(AF_MAX)));
  load_filter(ctx, "RestrictAddressFamilies");
}

void apply_memory_deny_write_execute() {
  scmp_filter_ctx ctx = seccomp_init(SCMP_ACT_ALLOW);
  const scmp_datum_t wx = PROT_WRITE | PROT_EXEC;
  seccomp_rule_add(ctx, SCMP_ACT_ERRNO(EPERM), SCMP_SYS(mmap), 1,
                   SCMP_A2(SCMP_CMP_MASKED_EQ, wx, wx));
  seccomp_rule_add(ctx, SCMP_ACT_ERRNO(EPERM), SCMP_SYS(mprotect), 1,
                   SCMP_A2(SCMP_CMP_MASKED_EQ, PROT_EXEC, PROT_EXEC));
  seccomp_rule_add(ctx, SCMP_ACT_ERRNO(EPERM), SCMP_SYS(pkey_mprotect), 1,
                   SCMP_A2(SCMP_CMP_MASKED_EQ, PROT_EXEC, PROT_EXEC));
  load_filter(ctx, "MemoryDenyWriteExecute");
}

void mount_private_proc(const std::string& protect_proc, const std::string& proc_subset) {
  if (::unshare(CLONE_NEWNS) != 0)
    fail(std::string("unshare(CLONE_NEWNS): ") + std::strerror(errno));
  if (::mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) != 0) {
    fail(std::string("making / private: ") + std::strerror(errno));
  }
  std::string options;
  if (!protect_proc.empty() && protect_proc != "default") options = "hidepid=" + protect_proc;
  if (proc_subset == "pid") options += std::string(options.empty() ? "" : ",") + "subset=pid";
  if (::mount("proc", "/proc", "proc", MS_NOSUID | MS_NODEV | MS_NOEXEC, options.c_str()) != 0) {
    fail("mounting /proc with " + options + ": " + std::strerror(errno));
  }
}

void cut_bounding_set(const std::set<std::string>& keep) {
  if (!keep.empty()) fail("only an empty CapabilityBoundingSet= is supported");
  for (int cap = 0; cap <= CAP_LAST_CAP; ++cap) {
    if (::prctl(PR_CAPBSET_DROP, cap, 0, 0, 0) != 0 && errno != EINVAL) {
      fail("dropping capability " + std::to_string(cap) + ": " + std::strerror(errno));
    }
  }
}

void become_unprivileged_user() {
  const gid_t nogroup = 65534;
  const uid_t nobody = 65534;
  if (::setgroups(0, nullptr) != 0 || ::setresgid(nogroup, nogroup, nogroup) != 0 ||
      ::setresuid(nobody, nobody, nobody) != 0) {
    fail(std::string("becoming user 65534: ") + std::strerror(errno));
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 2 && (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0)) {
    std::printf(
        "usage: unit_sandbox UNIT_FILE [KEY=VALUE...] -- PROGRAM [ARGS...]\n"
        "Runs PROGRAM under the system-call filter, address families, capability bounding set,\n"
        "no-new-privileges, resource limits and /proc view of UNIT_FILE's [Service] section, as\n"
        "an unprivileged user. KEY=VALUE overrides a setting. Needs root; exits 125 on set-up\n"
        "errors.\n");
    return 0;
  }
  int separator = 0;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--") == 0) {
      separator = i;
      break;
    }
  }
  if (argc < 4 || separator < 2 || separator + 1 >= argc) {
    fail("usage: unit_sandbox UNIT_FILE [KEY=VALUE...] -- PROGRAM [ARGS...] (--help)");
  }
  if (::geteuid() != 0) fail("needs root: it mounts a private /proc and drops to user 65534");

  auto settings = read_service_section(argv[1]);
  for (int i = 2; i < separator; ++i) {
    const std::string kv = argv[i];
    const auto eq = kv.find('=');
    if (eq == std::string::npos) fail("override " + kv + " is not KEY=VALUE");
    settings.emplace_back(kv.substr(0, eq), kv.substr(eq + 1));
  }
  std::vector<std::string> filter_lines;
  std::map<std::string, std::string> last;  // the last assignment of each key wins
  for (const auto& [key, value] : settings) {
    if (key == "SystemCallFilter") {
      filter_lines.push_back(value);
    } else {
      last[key] = value;
    }
  }

  if (last.count("ProtectProc") != 0 || last.count("ProcSubset") != 0) {
    mount_private_proc(last["ProtectProc"], last["ProcSubset"]);
  }
  for (const auto& [key, resource] :
       {std::pair{"LimitRTPRIO", RLIMIT_RTPRIO}, std::pair{"LimitNOFILE", RLIMIT_NOFILE}}) {
    if (last.count(key) == 0) continue;
    rlimit limit{limit_value(last[key]), limit_value(last[key])};
    if (::setrlimit(resource, &limit) != 0) {
      // Raising a hard limit needs CAP_SYS_RESOURCE, which containers often lack: run with the
      // most this machine allows and say so (tests read this line to know what they can check).
      rlimit now{};
      ::getrlimit(resource, &now);
      limit.rlim_cur = limit.rlim_max = std::min(limit.rlim_max, now.rlim_max);
      if (::setrlimit(resource, &limit) != 0) fail(std::string("setrlimit ") + key);
      std::fprintf(stderr,
                   "unit_sandbox: cannot raise %s to %s here (hard limit %llu): using %llu\n", key,
                   last[key].c_str(), static_cast<unsigned long long>(now.rlim_max),
                   static_cast<unsigned long long>(limit.rlim_cur));
    }
  }
  if (last.count("CapabilityBoundingSet") != 0) {
    const auto caps = words(last["CapabilityBoundingSet"]);
    cut_bounding_set({caps.begin(), caps.end()});
  }
  become_unprivileged_user();
  if (last["NoNewPrivileges"] == "yes" && ::prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0) {
    fail("PR_SET_NO_NEW_PRIVS");
  }
  if (last.count("RestrictAddressFamilies") != 0) {
    std::set<int> families;
    for (const auto& f : words(last["RestrictAddressFamilies"])) families.insert(address_family(f));
    apply_address_families(families);
  }
  if (last["MemoryDenyWriteExecute"] == "yes") apply_memory_deny_write_execute();
  if (!filter_lines.empty()) apply_syscall_filter(allowed_syscalls(filter_lines));

  ::execv(argv[separator + 1], argv + separator + 1);
  // execve is in every allow list (@default), so this is a missing or unreadable program.
  std::fprintf(stderr, "unit_sandbox: cannot run %s: %s\n", argv[separator + 1],
               std::strerror(errno));
  return 127;
}
