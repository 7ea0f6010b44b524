// posectl security init DIR: a DDS Security keystore for posed in SROS2's layout
// (tools/posectl/keystore.hpp): a CA, the governance document, and the enclaves "posed" (publishes
// rt/posed/*, rt/tf, rt/tf_static and rt/diagnostics) and "posectl" (reads them), plus one reader
// enclave per
// --reader NAME for the programs that consume posed's poses. Run again with other --reader names to
// add enclaves signed by the same CA. posed takes an enclave with `dds.security.enclave:
// DIR/enclaves/posed`, posectl echo with `--enclave DIR/enclaves/posectl` (docs/security.md). Exit
// codes: 0 written, 1 a file could not be made, 2 bad arguments.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <string>
#include <vector>

#include "tools/posectl/commands.hpp"
#include "tools/posectl/keystore.hpp"

namespace posed::posectl {

int run_security(int argc, char** argv) {
  CLI::App app{"DDS Security for posed's topics", "posectl security"};
  app.require_subcommand(1);
  CLI::App* init = app.add_subcommand(
      "init", "make (or extend) a keystore in SROS2's layout: CA, governance, enclaves");
  std::string dir;
  int domain_id = -1;
  int days = 3650;
  std::vector<std::string> readers;
  init->add_option("DIR", dir, "keystore directory (created)")->required();
  init->add_option("--domain", domain_id,
                   "the only DDS domain the documents allow (default: every domain, 0-230, the ids "
                   "DDS Security documents can name)")
      ->check(CLI::Range(0, 230));
  init->add_option("--days", days, "validity of certificates and permissions [days]")
      ->check(CLI::Range(1, 36500));
  init->add_option(
      "--reader", readers,
      "another enclave allowed to read rt/posed/*, rt/tf, rt/tf_static and rt/diagnostics "
      "(repeatable), e.g. a controller");
  CLI11_PARSE(app, argc, argv);

  KeystoreSpec spec;
  spec.dir = dir;
  spec.domain_id = domain_id;
  spec.valid_days = days;
  // posed reads one topic: the initial pose (RViz's 2D Pose Estimate, posectl initialpose).
  spec.enclaves.push_back({"posed", kPosedTopics, {kInitialPoseTopic}});
  spec.enclaves.push_back({"posectl", {kInitialPoseTopic}, kPosedTopics});
  for (const std::string& name : readers) {
    if (name.empty() || name.find_first_of("/. ") != std::string::npos) {
      std::fprintf(stderr, "posectl security init: --reader '%s': a plain name, no '/', '.', ' '\n",
                   name.c_str());
      return 2;
    }
    spec.enclaves.push_back({name, {}, kPosedTopics});
  }
  std::string error;
  if (!create_keystore(spec, error)) {
    std::fprintf(stderr, "posectl security init: %s\n", error.c_str());
    return 1;
  }
  std::printf("keystore %s: CA in public/ca.cert.pem (key in private/), governance for %s\n",
              dir.c_str(),
              domain_id < 0 ? "every domain" : ("domain " + std::to_string(domain_id)).c_str());
  for (const EnclaveSpec& e : spec.enclaves) {
    const auto list = [](const std::vector<std::string>& topics) {
      std::string s;
      for (const std::string& t : topics) s += (s.empty() ? "" : ", ") + t;
      return s.empty() ? std::string("nothing") : s;
    };
    std::printf("  enclaves/%-10s publishes %s; reads %s\n", e.name.c_str(),
                list(e.publish).c_str(), list(e.subscribe).c_str());
  }
  return 0;
}

}  // namespace posed::posectl
