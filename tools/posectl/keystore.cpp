#include "tools/posectl/keystore.hpp"

#include <openssl/bio.h>
#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/pem.h>
#include <openssl/pkcs7.h>
#include <openssl/x509.h>
#include <openssl/x509v3.h>

#include <ctime>
#include <filesystem>
#include <fstream>
#include <memory>
#include <tuple>

namespace posed::posectl {
namespace {

namespace fs = std::filesystem;

template <typename T, void (*Free)(T*)>
struct Deleter {
  void operator()(T* p) const { Free(p); }
};
using Key = std::unique_ptr<EVP_PKEY, Deleter<EVP_PKEY, EVP_PKEY_free>>;
using Cert = std::unique_ptr<X509, Deleter<X509, X509_free>>;
using Bio = std::unique_ptr<BIO, Deleter<BIO, BIO_free_all>>;
using Pkcs7 = std::unique_ptr<PKCS7, Deleter<PKCS7, PKCS7_free>>;

/// OpenSSL's reason for the last failure, e.g. "error:0480006C:PEM routines::no start line".
std::string openssl_reason() {
  const unsigned long code = ERR_get_error();
  if (code == 0) return "unknown OpenSSL error";
  char text[256];
  ERR_error_string_n(code, text, sizeof text);
  ERR_clear_error();
  return text;
}

bool write_text(const fs::path& path, const std::string& text, std::string& error,
                fs::perms mode = fs::perms::owner_read | fs::perms::owner_write |
                                 fs::perms::group_read | fs::perms::others_read) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  if (!out.flush()) {
    error = path.string() + ": cannot write";
    return false;
  }
  std::error_code ec;
  fs::permissions(path, mode, ec);
  return true;
}

/// The contents of a memory BIO.
std::string bio_text(BIO* bio) {
  char* data = nullptr;
  const long size = BIO_get_mem_data(bio, &data);
  return std::string(data, static_cast<std::size_t>(size));
}

Key make_key(std::string& error) {
  Key key(EVP_EC_gen("P-256"));  // prime256v1, as SROS2's keystores use
  if (!key) error = "EC P-256 key: " + openssl_reason();
  return key;
}

std::string key_pem(EVP_PKEY* key) {
  Bio bio(BIO_new(BIO_s_mem()));
  PEM_write_bio_PrivateKey(bio.get(), key, nullptr, nullptr, 0, nullptr, nullptr);
  return bio_text(bio.get());
}

std::string cert_pem(X509* cert) {
  Bio bio(BIO_new(BIO_s_mem()));
  PEM_write_bio_X509(bio.get(), cert);
  return bio_text(bio.get());
}

bool add_extension(X509* cert, X509* issuer, int nid, const char* value) {
  X509V3_CTX ctx;
  X509V3_set_ctx_nodb(&ctx);
  X509V3_set_ctx(&ctx, issuer, cert, nullptr, nullptr, 0);
  X509_EXTENSION* ext = X509V3_EXT_conf_nid(nullptr, &ctx, nid, value);
  if (ext == nullptr) return false;
  const bool ok = X509_add_ext(cert, ext, -1) == 1;
  X509_EXTENSION_free(ext);
  return ok;
}

/// A certificate for `subject_cn` with `key`'s public key, signed by `issuer_key` (self-signed
/// when `issuer` is null).
Cert make_cert(const std::string& subject_cn, EVP_PKEY* key, X509* issuer, EVP_PKEY* issuer_key,
               int valid_days, long serial, std::string& error) {
  Cert cert(X509_new());
  X509_set_version(cert.get(), 2);  // v3
  ASN1_INTEGER_set(X509_get_serialNumber(cert.get()), serial);
  X509_gmtime_adj(X509_getm_notBefore(cert.get()), 0);
  X509_gmtime_adj(X509_getm_notAfter(cert.get()), 60L * 60 * 24 * valid_days);
  X509_set_pubkey(cert.get(), key);
  X509_NAME* name = X509_get_subject_name(cert.get());
  X509_NAME_add_entry_by_txt(name, "CN", MBSTRING_UTF8,
                             reinterpret_cast<const unsigned char*>(subject_cn.c_str()), -1, -1, 0);
  X509_set_issuer_name(cert.get(), issuer != nullptr ? X509_get_subject_name(issuer) : name);
  X509* signer = issuer != nullptr ? issuer : cert.get();
  const bool is_ca = issuer == nullptr;
  if (!add_extension(cert.get(), signer, NID_basic_constraints,
                     is_ca ? "critical,CA:TRUE" : "critical,CA:FALSE") ||
      !add_extension(cert.get(), signer, NID_key_usage,
                     is_ca ? "critical,keyCertSign,cRLSign,digitalSignature"
                           : "critical,digitalSignature,keyAgreement") ||
      X509_sign(cert.get(), issuer_key, EVP_sha256()) == 0) {
    error = "certificate for " + subject_cn + ": " + openssl_reason();
    return nullptr;
  }
  return cert;
}

/// `document` signed by the CA as clear-signed S/MIME (multipart/signed, text/plain), which is
/// what `openssl smime -sign -text` writes and the DDS Security access control plugin verifies.
bool sign_document(const std::string& document, X509* ca, EVP_PKEY* ca_key, std::string& signed_out,
                   std::string& error) {
  const int flags = PKCS7_DETACHED | PKCS7_STREAM | PKCS7_TEXT;
  Bio in(BIO_new_mem_buf(document.data(), static_cast<int>(document.size())));
  Pkcs7 p7(PKCS7_sign(ca, ca_key, nullptr, in.get(), flags));
  if (!p7) {
    error = "signing: " + openssl_reason();
    return false;
  }
  Bio content(BIO_new_mem_buf(document.data(), static_cast<int>(document.size())));
  Bio out(BIO_new(BIO_s_mem()));
  if (SMIME_write_PKCS7(out.get(), p7.get(), content.get(), flags) != 1) {
    error = "writing S/MIME: " + openssl_reason();
    return false;
  }
  signed_out = bio_text(out.get());
  return true;
}

std::string iso_time(std::time_t t) {
  std::tm tm{};
  ::gmtime_r(&t, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%S", &tm);
  return text;
}

std::string domains_xml(int domain_id, const std::string& indent) {
  if (domain_id < 0) {
    return indent + "<domains>\n" + indent + "  <id_range><min>0</min><max>230</max></id_range>\n" +
           indent + "</domains>\n";
  }
  return indent + "<domains>\n" + indent + "  <id>" + std::to_string(domain_id) + "</id>\n" +
         indent + "</domains>\n";
}

// Everything protected: only authenticated participants with permissions join, discovery and
// liveliness are encrypted, every topic needs read and write permission and its data and
// metadata are encrypted (SROS2's default governance, whose "*" rule posed keeps).
std::string governance_xml(int domain_id) {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         "<dds xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" "
         "xsi:noNamespaceSchemaLocation=\"http://www.omg.org/spec/DDS-SECURITY/20170901/"
         "omg_shared_ca_governance.xsd\">\n"
         "  <domain_access_rules>\n"
         "    <domain_rule>\n" +
         domains_xml(domain_id, "      ") +
         "      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>\n"
         "      <enable_join_access_control>true</enable_join_access_control>\n"
         "      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>\n"
         "      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>\n"
         "      <rtps_protection_kind>SIGN</rtps_protection_kind>\n"
         "      <topic_access_rules>\n"
         "        <topic_rule>\n"
         "          <topic_expression>*</topic_expression>\n"
         "          <enable_discovery_protection>true</enable_discovery_protection>\n"
         "          <enable_liveliness_protection>true</enable_liveliness_protection>\n"
         "          <enable_read_access_control>true</enable_read_access_control>\n"
         "          <enable_write_access_control>true</enable_write_access_control>\n"
         "          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>\n"
         "          <data_protection_kind>ENCRYPT</data_protection_kind>\n"
         "        </topic_rule>\n"
         "      </topic_access_rules>\n"
         "    </domain_rule>\n"
         "  </domain_access_rules>\n"
         "</dds>\n";
}

std::string topics_xml(const char* kind, const std::vector<std::string>& topics) {
  if (topics.empty()) return "";
  std::string xml = std::string("        <") + kind + ">\n          <topics>\n";
  for (const auto& t : topics) xml += "            <topic>" + t + "</topic>\n";
  return xml + "          </topics>\n        </" + kind + ">\n";
}

std::string permissions_xml(const EnclaveSpec& enclave, int domain_id, int valid_days) {
  const std::time_t now = std::time(nullptr);
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         "<dds xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" "
         "xsi:noNamespaceSchemaLocation=\"http://www.omg.org/spec/DDS-SECURITY/20170901/"
         "omg_shared_ca_permissions.xsd\">\n"
         "  <permissions>\n"
         "    <grant name=\"/" +
         enclave.name +
         "\">\n"
         "      <subject_name>CN=/" +
         enclave.name +
         "</subject_name>\n"
         "      <validity>\n"
         "        <not_before>" +
         iso_time(now - 60) + "</not_before>\n        <not_after>" +
         iso_time(now + 60L * 60 * 24 * valid_days) +
         "</not_after>\n"
         "      </validity>\n"
         "      <allow_rule>\n" +
         domains_xml(domain_id, "        ") + topics_xml("publish", enclave.publish) +
         topics_xml("subscribe", enclave.subscribe) +
         "      </allow_rule>\n"
         "      <default>DENY</default>\n"
         "    </grant>\n"
         "  </permissions>\n"
         "</dds>\n";
}

bool load_ca(const fs::path& dir, Key& key, Cert& cert, std::string& error) {
  const fs::path key_path = dir / "private" / "ca.key.pem";
  const fs::path cert_path = dir / "public" / "ca.cert.pem";
  Bio key_bio(BIO_new_file(key_path.c_str(), "r"));
  Bio cert_bio(BIO_new_file(cert_path.c_str(), "r"));
  if (!key_bio || !cert_bio) {
    error = (key_bio ? cert_path : key_path).string() + ": cannot open";
    return false;
  }
  key.reset(PEM_read_bio_PrivateKey(key_bio.get(), nullptr, nullptr, nullptr));
  cert.reset(PEM_read_bio_X509(cert_bio.get(), nullptr, nullptr, nullptr));
  if (!key || !cert) {
    error = (key ? cert_path : key_path).string() + ": " + openssl_reason();
    return false;
  }
  return true;
}

}  // namespace

bool create_keystore(const KeystoreSpec& spec, std::string& error) {
  const fs::path dir = spec.dir;
  std::error_code ec;
  for (const char* sub : {"public", "private", "enclaves"}) fs::create_directories(dir / sub, ec);
  if (ec) {
    error = (dir / "enclaves").string() + ": " + ec.message();
    return false;
  }
  fs::permissions(dir / "private", fs::perms::owner_all, ec);
  const fs::perms secret = fs::perms::owner_read | fs::perms::owner_write;

  Key ca_key;
  Cert ca_cert;
  if (fs::exists(dir / "private" / "ca.key.pem")) {
    if (!load_ca(dir, ca_key, ca_cert, error)) return false;
  } else {
    ca_key = make_key(error);
    if (!ca_key) return false;
    ca_cert = make_cert("posed keystore CA", ca_key.get(), nullptr, ca_key.get(), spec.valid_days,
                        1, error);
    if (!ca_cert) return false;
    const std::string pem = cert_pem(ca_cert.get());
    if (!write_text(dir / "private" / "ca.key.pem", key_pem(ca_key.get()), error, secret) ||
        !write_text(dir / "public" / "ca.cert.pem", pem, error)) {
      return false;
    }
  }
  // One CA serves as both, under the names SROS2's tools look for: symbolic links to ca.*.pem,
  // as `ros2 security create_keystore` makes them.
  const std::string ca_pem = cert_pem(ca_cert.get());
  for (const auto& [folder, link, target] :
       {std::tuple{"public", "identity_ca.cert.pem", "ca.cert.pem"},
        std::tuple{"public", "permissions_ca.cert.pem", "ca.cert.pem"},
        std::tuple{"private", "identity_ca.key.pem", "ca.key.pem"},
        std::tuple{"private", "permissions_ca.key.pem", "ca.key.pem"}}) {
    const fs::path path = dir / folder / link;
    fs::remove(path, ec);
    fs::create_symlink(target, path, ec);
    if (ec) {
      error = path.string() + ": " + ec.message();
      return false;
    }
  }

  std::string governance_p7s;
  const std::string governance = governance_xml(spec.domain_id);
  if (!sign_document(governance, ca_cert.get(), ca_key.get(), governance_p7s, error)) {
    error = "governance " + error;
    return false;
  }
  if (!write_text(dir / "enclaves" / "governance.xml", governance, error) ||
      !write_text(dir / "enclaves" / "governance.p7s", governance_p7s, error)) {
    return false;
  }

  long serial = static_cast<long>(std::time(nullptr));
  for (const EnclaveSpec& enclave : spec.enclaves) {
    const fs::path out = dir / "enclaves" / enclave.name;
    fs::create_directories(out, ec);
    if (ec) {
      error = out.string() + ": " + ec.message();
      return false;
    }
    Key key = make_key(error);
    if (!key) return false;
    Cert cert = make_cert("/" + enclave.name, key.get(), ca_cert.get(), ca_key.get(),
                          spec.valid_days, ++serial, error);
    if (!cert) return false;
    const std::string permissions = permissions_xml(enclave, spec.domain_id, spec.valid_days);
    std::string permissions_p7s;
    if (!sign_document(permissions, ca_cert.get(), ca_key.get(), permissions_p7s, error)) {
      error = out.string() + " permissions " + error;
      return false;
    }
    if (!write_text(out / "key.pem", key_pem(key.get()), error, secret) ||
        !write_text(out / "cert.pem", cert_pem(cert.get()), error) ||
        !write_text(out / "identity_ca.cert.pem", ca_pem, error) ||
        !write_text(out / "permissions_ca.cert.pem", ca_pem, error) ||
        !write_text(out / "governance.p7s", governance_p7s, error) ||
        !write_text(out / "permissions.xml", permissions, error) ||
        !write_text(out / "permissions.p7s", permissions_p7s, error)) {
      return false;
    }
  }
  return true;
}

}  // namespace posed::posectl
