#include "daemon/dds/participant.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>

#include "daemon/dds/generated_types.hpp"

namespace posed::dds::detail {
namespace {

struct DomainEntry {
  dds_entity_t domain = 0;
  std::string xml_path;
  int refs = 0;
};

/// Domains this process created from an XML file, by id (see Participant).
std::mutex g_domains_mutex;
std::map<std::uint32_t, DomainEntry>& domains() {
  static std::map<std::uint32_t, DomainEntry> entries;
  return entries;
}

bool read_file(const std::string& path, std::string& text, std::string& error) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    error = "cyclonedds config " + path + ": cannot open: " + std::strerror(errno);
    return false;
  }
  std::ostringstream buffer;
  buffer << in.rdbuf();
  text = buffer.str();
  if (text.find('<') == std::string::npos) {
    error = "cyclonedds config " + path + ": not an XML file (no element)";
    return false;
  }
  return true;
}

/// Takes a reference on the domain `config` names, creating it from the XML file if needed.
bool acquire_domain(const DdsConfig& config, std::string& error) {
  std::lock_guard lock(g_domains_mutex);
  auto& entries = domains();
  if (auto it = entries.find(config.domain_id); it != entries.end()) {
    if (it->second.xml_path != config.cyclonedds_xml_path) {
      error = "cyclonedds config " + config.cyclonedds_xml_path + ": domain " +
              std::to_string(config.domain_id) + " already runs in this process with " +
              it->second.xml_path;
      return false;
    }
    ++it->second.refs;
    return true;
  }
  std::string xml;
  if (!read_file(config.cyclonedds_xml_path, xml, error)) return false;
  // Passing the XML text (not a file:// URI) keeps CYCLONEDDS_URI and the working directory out
  // of the daemon's behaviour.
  const dds_entity_t domain = dds_create_domain(config.domain_id, xml.c_str());
  if (domain < 0) {
    error = "cyclonedds config " + config.cyclonedds_xml_path + ": domain " +
            std::to_string(config.domain_id) + " not created: " + dds_strretcode(domain);
    if (domain == DDS_RETCODE_PRECONDITION_NOT_MET) {
      error += " (the domain already exists in this process, created without this file)";
    } else {
      error += " (Cyclone printed the offending element above)";
    }
    return false;
  }
  entries[config.domain_id] = DomainEntry{domain, config.cyclonedds_xml_path, 1};
  return true;
}

void release_domain(std::uint32_t domain_id) {
  std::lock_guard lock(g_domains_mutex);
  auto& entries = domains();
  auto it = entries.find(domain_id);
  if (it == entries.end()) return;
  if (--it->second.refs == 0) {
    dds_delete(it->second.domain);
    entries.erase(it);
  }
}

}  // namespace

const dds_topic_descriptor_t& descriptor(Topic topic) {
  switch (topic) {
    case Topic::kOdom:
      return nav_msgs_msg_dds__Odometry__desc;
    case Topic::kPose:
      return geometry_msgs_msg_dds__PoseStamped__desc;
    case Topic::kStatus:
      return posed_msgs_msg_dds__Status__desc;
    case Topic::kTf:
    case Topic::kTfStatic:
      return tf2_msgs_msg_dds__TFMessage__desc;
    case Topic::kPath:
      return nav_msgs_msg_dds__Path__desc;
    case Topic::kDiagnostics:
      return diagnostic_msgs_msg_dds__DiagnosticArray__desc;
    case Topic::kCloud:
    case Topic::kMap:
      return sensor_msgs_msg_dds__PointCloud2__desc;
    case Topic::kImage:
      return sensor_msgs_msg_dds__CompressedImage__desc;
  }
  return nav_msgs_msg_dds__Odometry__desc;
}

namespace {

/// The participant QoS that turns on Cyclone's builtin DDS Security plugins (authentication,
/// access control, cryptography; Debian's libddsc0debian ships them and libddsc finds them by
/// their default names), or nullptr for plain DDS. Every file must be readable now: a typo
/// fails at start-up, naming the key, not as a handshake that silently never completes.
dds_qos_t* security_qos(const DdsSecurityFiles& files, std::string& error) {
  if (!files.enabled()) return nullptr;
  const std::pair<const char*, const std::string*> properties[] = {
      {"dds.sec.auth.identity_ca", &files.identity_ca},
      {"dds.sec.auth.identity_certificate", &files.identity_certificate},
      {"dds.sec.auth.private_key", &files.private_key},
      {"dds.sec.access.permissions_ca", &files.permissions_ca},
      {"dds.sec.access.governance", &files.governance},
      {"dds.sec.access.permissions", &files.permissions},
  };
  for (const auto& [property, path] : properties) {
    std::ifstream in(*path);
    if (path->empty() || !in) {
      error = std::string("DDS Security: ") + property + " " +
              (path->empty() ? std::string("is not set")
                             : *path + ": cannot read: " + std::strerror(errno));
      return nullptr;
    }
  }
  dds_qos_t* qos = dds_create_qos();
  for (const auto& [property, path] : properties) {
    dds_qset_prop(qos, property, ("file:" + *path).c_str());
  }
  // The plugins by their default names: libddsc looks for lib<name>.so where its package put them.
  const char* plugins[][4] = {
      {"auth", "dds_security_auth", "init_authentication", "finalize_authentication"},
      {"crypto", "dds_security_crypto", "init_crypto", "finalize_crypto"},
      {"access", "dds_security_ac", "init_access_control", "finalize_access_control"}};
  for (const auto& [kind, library, init, finalize] : plugins) {
    const std::string prefix = std::string("dds.sec.") + kind + ".library.";
    dds_qset_prop(qos, (prefix + "path").c_str(), library);
    dds_qset_prop(qos, (prefix + "init").c_str(), init);
    dds_qset_prop(qos, (prefix + "finalize").c_str(), finalize);
  }
  return qos;
}

}  // namespace

std::unique_ptr<Participant> Participant::open(const DdsConfig& config, std::string& error) {
  dds_qos_t* qos = security_qos(config.security, error);
  if (config.security.enabled() && qos == nullptr) return nullptr;
  const bool from_file = !config.cyclonedds_xml_path.empty();
  if (from_file && !acquire_domain(config, error)) {
    if (qos != nullptr) dds_delete_qos(qos);
    return nullptr;
  }
  const dds_entity_t participant = dds_create_participant(config.domain_id, qos, nullptr);
  if (qos != nullptr) dds_delete_qos(qos);
  if (participant < 0) {
    error = "DDS participant on domain " + std::to_string(config.domain_id) + ": " +
            dds_strretcode(participant);
    error += from_file ? " (cyclonedds config " + config.cyclonedds_xml_path + ")"
                       : " (config from CYCLONEDDS_URI or Cyclone's default)";
    if (config.security.enabled()) {
      error += "; DDS Security with " + config.security.identity_certificate +
               " (Cyclone logged the reason above: e.g. a file the CA did not sign, a domain the "
               "governance does not name, or permissions for another subject)";
    }
    if (from_file) release_domain(config.domain_id);
    return nullptr;
  }
  return std::unique_ptr<Participant>(new Participant(participant, config.domain_id, from_file));
}

Participant::Participant(dds_entity_t participant, std::uint32_t domain_id, bool holds_domain_ref)
    : participant_(participant), domain_id_(domain_id), holds_domain_ref_(holds_domain_ref) {}

Participant::~Participant() {
  dds_delete(participant_);  // deletes its topics, writers, readers and waitsets too
  if (holds_domain_ref_) release_domain(domain_id_);
}

dds_qos_t* make_topic_qos(Topic topic) {
  dds_qos_t* qos = dds_create_qos();
  // A reliable writer whose readers' buffers are full waits at most this long in dds_write,
  // so a stalled subscriber costs the publishing thread a bounded time, never a hang.
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(10));
  if (transient_local(topic)) {
    // tf2_ros::StaticBroadcasterQoS: transient-local, and the one latest message holds every
    // static transform (a static broadcaster resends them all when one changes). The map is
    // published as map servers do: the latest one reaches a reader that joins later.
    dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
  } else if (large_messages(topic)) {
    // A scan is ~1.2 MB, an image ~50 kB: two held per reader bound the memory a slow reader
    // costs; an older one is worth nothing once a newer one exists.
    dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 2);
  } else {
    dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 10);
  }
  const dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
  dds_qset_data_representation(qos, 1, &xcdr1);
  return qos;
}

dds_entity_t create_topic(dds_entity_t participant, Topic topic, std::string& error) {
  const std::string name(topic_name(topic));
  dds_qos_t* qos = make_topic_qos(topic);
  const dds_entity_t handle =
      dds_create_topic(participant, &descriptor(topic), name.c_str(), qos, nullptr);
  dds_delete_qos(qos);
  if (handle < 0) error = describe_error(name + ": create topic", handle);
  return handle;
}

dds_qos_t* make_initial_pose_qos() {
  dds_qos_t* qos = dds_create_qos();
  // RViz creates its publisher with rclcpp::QoS(5): ROS 2's default profile at a depth of 5.
  // Volatile: a pose given before posed started is stale, not an instruction to replay.
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 5);
  const dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
  dds_qset_data_representation(qos, 1, &xcdr1);
  return qos;
}

dds_entity_t create_initial_pose_topic(dds_entity_t participant, const std::string& name,
                                       std::string& error) {
  dds_qos_t* qos = make_initial_pose_qos();
  const dds_entity_t handle =
      dds_create_topic(participant, &geometry_msgs_msg_dds__PoseWithCovarianceStamped__desc,
                       name.c_str(), qos, nullptr);
  dds_delete_qos(qos);
  if (handle < 0) error = describe_error(name + ": create topic", handle);
  return handle;
}

std::string describe_error(std::string_view what, dds_return_t rc) {
  return std::string(what) + ": " + dds_strretcode(rc);
}

}  // namespace posed::dds::detail

namespace posed::dds {

DdsSecurityFiles DdsSecurityFiles::from_enclave(const std::string& dir) {
  const std::string d = dir.empty() || dir.back() == '/' ? dir : dir + "/";
  return {d + "identity_ca.cert.pem",    d + "cert.pem",       d + "key.pem",
          d + "permissions_ca.cert.pem", d + "governance.p7s", d + "permissions.p7s"};
}

}  // namespace posed::dds
