#pragma once
// A DDS Security keystore in SROS2's layout, made with OpenSSL's library: one CA (EC P-256) that
// is both identity CA and permissions CA, a governance document for posed's domain, and per
// enclave a key, a certificate the CA signed, and permissions for its topics, the documents
// signed by the CA as S/MIME (what `openssl smime -sign -text` writes and Cyclone DDS's access
// control plugin reads):
//   DIR/public/{ca,identity_ca,permissions_ca}.cert.pem   DIR/private/ca.key.pem
//   DIR/enclaves/governance.{xml,p7s}
//   DIR/enclaves/NAME/{cert.pem,key.pem,identity_ca.cert.pem,permissions_ca.cert.pem,
//                      governance.p7s,permissions.xml,permissions.p7s}

#include <string>
#include <vector>

namespace posed::posectl {

/// What posed writes and its readers read: its own topics and the tf tree.
inline const std::vector<std::string> kPosedTopics = {"rt/posed/*", "rt/tf", "rt/tf_static",
                                                      "rt/diagnostics"};

/// What posed reads: the initial pose for localisation on a saved map (RViz's 2D Pose Estimate).
inline const std::string kInitialPoseTopic = "rt/initialpose";

struct EnclaveSpec {
  std::string name;                  ///< "posed" -> enclaves/posed, subject CN=/posed
  std::vector<std::string> publish;  ///< DDS topic names or fnmatch patterns ("rt/posed/*")
  std::vector<std::string> subscribe;
};

struct KeystoreSpec {
  std::string dir;
  int domain_id = -1;  ///< the one domain the documents allow; -1: every domain (0-230)
  int valid_days = 3650;
  std::vector<EnclaveSpec> enclaves;
};

/// Creates the keystore (the CA only if DIR/private/ca.key.pem is absent, so enclaves can be
/// added to an existing keystore). Returns false with `error` naming the file that failed.
bool create_keystore(const KeystoreSpec& spec, std::string& error);

}  // namespace posed::posectl
