#include "rccx/net/certs.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <openssl/bio.h>
#include <openssl/bn.h>
#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/pem.h>
#include <openssl/pkcs7.h>
#include <openssl/rand.h>
#include <openssl/x509.h>
#include <openssl/x509v3.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <memory>
#include <system_error>

namespace rccx::net {

namespace fs = std::filesystem;
using Clock = std::chrono::system_clock;

namespace {

// OpenSSL's objects, freed by their own functions.
struct Free {
  void operator()(EVP_PKEY* p) const { EVP_PKEY_free(p); }
  void operator()(X509* p) const { X509_free(p); }
  void operator()(BIO* p) const { BIO_free_all(p); }
  void operator()(PKCS7* p) const { PKCS7_free(p); }
  void operator()(BIGNUM* p) const { BN_free(p); }
  void operator()(X509_EXTENSION* p) const { X509_EXTENSION_free(p); }
};
using Key = std::unique_ptr<EVP_PKEY, Free>;
using Cert = std::unique_ptr<X509, Free>;
using Bio = std::unique_ptr<BIO, Free>;

/// Throws NetError "<what>: <OpenSSL's reason>" (the queue's oldest error).
[[noreturn]] void openssl_failed(std::string_view what) {
  const unsigned long e = ERR_get_error();
  char text[256] = "unknown OpenSSL error";
  if (e != 0) ERR_error_string_n(e, text, sizeof text);
  ERR_clear_error();
  throw NetError(fmt::format("{}: {}", what, text));
}

template <typename T>
T* must(T* p, std::string_view what) {
  if (p == nullptr) openssl_failed(what);
  return p;
}
void must(int ok, std::string_view what) {
  if (ok <= 0) openssl_failed(what);
}

Key new_p256_key() {
  return Key(must(EVP_PKEY_Q_keygen(nullptr, nullptr, "EC", "P-256"), "an EC P-256 key"));
}

std::string bio_text(BIO* b) {
  char* data = nullptr;
  const long n = BIO_get_mem_data(b, &data);
  return std::string(data, static_cast<std::size_t>(n));
}

std::string pem_of(const X509* cert) {
  const Bio b(must(BIO_new(BIO_s_mem()), "a memory BIO"));
  must(PEM_write_bio_X509(b.get(), cert), "writing a certificate");
  return bio_text(b.get());
}

std::string pem_of(EVP_PKEY* key) {
  const Bio b(must(BIO_new(BIO_s_mem()), "a memory BIO"));
  // Not encrypted: Cyclone reads it unattended (the file's mode 0600 protects it).
  must(PEM_write_bio_PrivateKey(b.get(), key, nullptr, nullptr, 0, nullptr, nullptr),
       "writing a private key");
  return bio_text(b.get());
}

/// Writes `text` to `path` with `mode`, by a temporary file renamed over it: a reader never
/// sees half a file, and a failure leaves the old one.
void write_file(const fs::path& path, const std::string& text, mode_t mode) {
  const std::string tmp = path.string() + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, mode);
  if (fd < 0) {
    throw NetError(fmt::format("cannot write {}: {}", tmp, std::strerror(errno)));
  }
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int e = errno;
      ::close(fd);
      ::unlink(tmp.c_str());
      throw NetError(fmt::format("cannot write {}: {}", tmp, std::strerror(e)));
    }
    done += static_cast<std::size_t>(n);
  }
  // open's mode is cut by the umask; the key's 0600 must hold whatever it is.
  const bool ok = ::fchmod(fd, mode) == 0 && ::fsync(fd) == 0;
  const int e = errno;
  ::close(fd);
  if (!ok || ::rename(tmp.c_str(), path.c_str()) != 0) {
    ::unlink(tmp.c_str());
    throw NetError(
        fmt::format("cannot write {}: {}", path.string(), std::strerror(ok ? errno : e)));
  }
}

void make_dir(const fs::path& dir, mode_t mode) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw NetError(fmt::format("cannot make directory {}: {}", dir.string(), ec.message()));
  if (::chmod(dir.c_str(), mode) != 0) {
    throw NetError(
        fmt::format("cannot set the mode of {}: {}", dir.string(), std::strerror(errno)));
  }
}

std::time_t to_time_t(Clock::time_point t) {
  return Clock::to_time_t(t);
}

void add_extension(X509* cert, X509* issuer, int nid, const char* value) {
  X509V3_CTX ctx;
  X509V3_set_ctx(&ctx, issuer, cert, nullptr, nullptr, 0);
  const std::unique_ptr<X509_EXTENSION, Free> ext(
      must(X509V3_EXT_conf_nid(nullptr, &ctx, nid, value), fmt::format("the extension {}", value)));
  must(X509_add_ext(cert, ext.get(), -1), "adding an extension");
}

struct Subject {
  std::string common_name;
  std::string organizational_unit;  ///< "" for none
};

/// An X.509 v3 certificate for `key` with `subject`, signed by `issuer_key` (and `issuer`'s
/// name; self-signed when issuer is null), valid from `from` to `to`.
Cert make_cert(EVP_PKEY* key, const Subject& subject, X509* issuer, EVP_PKEY* issuer_key,
               bool is_ca, Clock::time_point from, Clock::time_point to) {
  Cert cert(must(X509_new(), "a certificate"));
  must(X509_set_version(cert.get(), 2), "the certificate's version");  // 2: X.509 v3
  // A random 63-bit serial: unique enough for a cell's few certificates, and positive.
  unsigned char serial[8];
  must(RAND_bytes(serial, sizeof serial), "a random serial number");
  serial[0] &= 0x7f;
  const std::unique_ptr<BIGNUM, Free> bn(
      must(BN_bin2bn(serial, sizeof serial, nullptr), "a serial number"));
  must(BN_to_ASN1_INTEGER(bn.get(), X509_get_serialNumber(cert.get())) != nullptr ? 1 : 0,
       "the serial number");
  must(ASN1_TIME_set(X509_getm_notBefore(cert.get()), to_time_t(from)) != nullptr ? 1 : 0,
       "not before");
  must(ASN1_TIME_set(X509_getm_notAfter(cert.get()), to_time_t(to)) != nullptr ? 1 : 0,
       "not after");
  X509_NAME* name = X509_get_subject_name(cert.get());
  const auto add_entry = [&](const char* field, const std::string& value) {
    must(X509_NAME_add_entry_by_txt(name, field, MBSTRING_UTF8,
                                    reinterpret_cast<const unsigned char*>(value.c_str()), -1, -1,
                                    0),
         "the certificate's subject");
  };
  add_entry("O", "rccx");
  if (!subject.organizational_unit.empty()) add_entry("OU", subject.organizational_unit);
  add_entry("CN", subject.common_name);
  X509* signer = issuer != nullptr ? issuer : cert.get();
  must(X509_set_issuer_name(cert.get(), X509_get_subject_name(signer)), "the issuer");
  must(X509_set_pubkey(cert.get(), key), "the public key");
  if (is_ca) {
    add_extension(cert.get(), signer, NID_basic_constraints, "critical,CA:TRUE");
    add_extension(cert.get(), signer, NID_key_usage,
                  "critical,keyCertSign,cRLSign,digitalSignature");
  } else {
    add_extension(cert.get(), signer, NID_basic_constraints, "critical,CA:FALSE");
    add_extension(cert.get(), signer, NID_key_usage, "critical,digitalSignature,keyAgreement");
  }
  add_extension(cert.get(), signer, NID_subject_key_identifier, "hash");
  add_extension(cert.get(), signer, NID_authority_key_identifier, "keyid:always");
  must(X509_sign(cert.get(), issuer_key, EVP_sha256()), "signing the certificate");
  return cert;
}

/// `text` signed by `cert`/`key` as S/MIME (PKCS#7, detached, text): what Cyclone's access
/// control plugin verifies against dds.sec.access.permissions_ca.
std::string smime_signed(const std::string& text, X509* cert, EVP_PKEY* key) {
  const int flags = PKCS7_DETACHED | PKCS7_TEXT | PKCS7_STREAM;
  const Bio in(must(BIO_new_mem_buf(text.data(), static_cast<int>(text.size())), "a memory BIO"));
  const std::unique_ptr<PKCS7, Free> p7(
      must(PKCS7_sign(cert, key, nullptr, in.get(), flags), "signing a document (PKCS#7)"));
  const Bio out(must(BIO_new(BIO_s_mem()), "a memory BIO"));
  // Streaming: the content is read from `in` as it is written out, beside its signature.
  must(SMIME_write_PKCS7(out.get(), p7.get(), in.get(), flags), "writing S/MIME");
  return bio_text(out.get());
}

Key read_key(const fs::path& path) {
  const Bio b(BIO_new_file(path.c_str(), "r"));
  if (!b) openssl_failed(fmt::format("cannot read {}", path.string()));
  return Key(must(PEM_read_bio_PrivateKey(b.get(), nullptr, nullptr, nullptr),
                  fmt::format("the private key in {}", path.string())));
}

Cert read_cert(const fs::path& path) {
  const Bio b(BIO_new_file(path.c_str(), "r"));
  if (!b) openssl_failed(fmt::format("cannot read {}", path.string()));
  return Cert(must(PEM_read_bio_X509(b.get(), nullptr, nullptr, nullptr),
                   fmt::format("the certificate in {}", path.string())));
}

/// "2025-03-01T12:00:00": the permissions' dates, in UTC (DDS Security's xs:dateTime).
std::string xml_date(Clock::time_point t) {
  const std::time_t tt = to_time_t(t);
  std::tm tm{};
  gmtime_r(&tt, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%S", &tm);
  return text;
}

constexpr const char* kIdentityCa = "identity_ca.pem";
constexpr const char* kPermissionsCa = "permissions_ca.pem";
constexpr const char* kIdentityCaKey = "private/identity_ca_key.pem";
constexpr const char* kPermissionsCaKey = "private/permissions_ca_key.pem";

}  // namespace

Grants program_grants() {
  return {{kRequestTopic, kFrameTopic, kHeartbeatTopic},
          {kStateTopic, kAckTopic, kEventTopic, kHeartbeatTopic, kClaimTopic}};
}

Grants serve_grants() {
  return {{kStateTopic, kAckTopic, kEventTopic, kClaimTopic, kHeartbeatTopic, "rt/*"},
          {kRequestTopic, kFrameTopic, kHeartbeatTopic, kClaimTopic, kStateTopic}};
}

Role role_of(std::string_view name) {
  return name.substr(0, 7) == "program" ? Role::program : Role::serve;
}

void check_participant_name(std::string_view name) {
  bool ok = !name.empty() && name.size() <= 32;
  for (const char c : name) {
    ok = ok && ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                c == '_' || c == '-');
  }
  if (!ok) {
    throw NetError(
        fmt::format("participant name '{}': give 1 to 32 letters, digits, '_' or '-' (it is the "
                    "certificate's CN and a directory's name)",
                    name));
  }
}

std::string governance_xml(Protection protection) {
  const char* const headers = protection == Protection::full ? "ENCRYPT" : "NONE";
  // One domain rule for every domain rccx allows. Topic rules are taken in order, the first
  // that matches a topic's name applies: rccx's own topics fully protected; ROS 2's rt/* readable
  // by any authenticated participant (ROS 2 tools with their own certificates of this CA) but
  // written only by those whose permissions say so (serve processes); anything else fully
  // protected, so a topic nobody granted is closed.
  std::string topics;
  const auto rule = [&](const char* expression, bool read_controlled) {
    topics += fmt::format(
        "        <topic_rule>\n"
        "          <topic_expression>{}</topic_expression>\n"
        "          <enable_discovery_protection>true</enable_discovery_protection>\n"
        "          <enable_liveliness_protection>true</enable_liveliness_protection>\n"
        "          <enable_read_access_control>{}</enable_read_access_control>\n"
        "          <enable_write_access_control>true</enable_write_access_control>\n"
        "          <metadata_protection_kind>{}</metadata_protection_kind>\n"
        "          <data_protection_kind>ENCRYPT</data_protection_kind>\n"
        "        </topic_rule>\n",
        expression, read_controlled ? "true" : "false", headers);
  };
  rule("rccx_*", true);
  rule("rt/*", false);
  rule("*", true);
  return fmt::format(
      "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
      "<dds xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\"\n"
      "     xsi:noNamespaceSchemaLocation=\"http://www.omg.org/spec/DDS-SECURITY/20170901/"
      "omg_shared_ca_governance.xsd\">\n"
      "  <domain_access_rules>\n"
      "    <domain_rule>\n"
      "      <domains><id_range><min>0</min><max>230</max></id_range></domains>\n"
      "      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>\n"
      "      <enable_join_access_control>true</enable_join_access_control>\n"
      "      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>\n"
      "      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>\n"
      "      <rtps_protection_kind>{}</rtps_protection_kind>\n"
      "      <topic_access_rules>\n"
      "{}"
      "      </topic_access_rules>\n"
      "    </domain_rule>\n"
      "  </domain_access_rules>\n"
      "</dds>\n",
      headers, topics);
}

std::string permissions_xml(const std::string& subject, const Grants& grants,
                            Clock::time_point from, Clock::time_point to) {
  const auto topic_list = [](const std::vector<std::string>& names) {
    std::string out;
    for (const std::string& n : names) out += fmt::format("            <topic>{}</topic>\n", n);
    return out;
  };
  // The grant's name is for people: the subject's CN ("puma").
  const std::size_t cn = subject.rfind("CN=");
  const std::string grant_name = cn == std::string::npos ? subject : subject.substr(cn + 3);
  std::string rule;
  if (!grants.publish.empty()) {
    rule += fmt::format(
        "        <publish>\n          <topics>\n{}          </topics>\n"
        "        </publish>\n",
        topic_list(grants.publish));
  }
  if (!grants.subscribe.empty()) {
    rule += fmt::format(
        "        <subscribe>\n          <topics>\n{}          </topics>\n"
        "        </subscribe>\n",
        topic_list(grants.subscribe));
  }
  return fmt::format(
      "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
      "<dds xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\"\n"
      "     xsi:noNamespaceSchemaLocation=\"http://www.omg.org/spec/DDS-SECURITY/20170901/"
      "omg_shared_ca_permissions.xsd\">\n"
      "  <permissions>\n"
      "    <grant name=\"{4}\">\n"
      "      <subject_name>{0}</subject_name>\n"
      "      <validity>\n"
      "        <not_before>{1}</not_before>\n"
      "        <not_after>{2}</not_after>\n"
      "      </validity>\n"
      "      <allow_rule>\n"
      "        <domains><id_range><min>0</min><max>230</max></id_range></domains>\n"
      "{3}"
      "      </allow_rule>\n"
      "      <default>DENY</default>\n"
      "    </grant>\n"
      "  </permissions>\n"
      "</dds>\n",
      subject, xml_date(from), xml_date(to), rule, grant_name);
}

void make_ca(const fs::path& dir, const CaOptions& options) {
  if (options.days < 1 || options.days > 36500) {
    throw NetError(fmt::format("CA validity {} days: give 1 .. 36500", options.days));
  }
  if (!options.force && (fs::exists(dir / kIdentityCa) || fs::exists(dir / kIdentityCaKey))) {
    throw NetError(fmt::format(
        "{} has a CA already ({}): give --force to replace it (every participant must then be "
        "issued again), or `rccx certs add {} --participant NAME` to add one",
        dir.string(), (dir / kIdentityCa).string(), dir.string()));
  }
  make_dir(dir, 0755);
  make_dir(dir / "private", 0700);
  const Clock::time_point from = Clock::now() - std::chrono::hours(1);
  const Clock::time_point to = Clock::now() + std::chrono::hours(24) * options.days;
  const Key identity_key = new_p256_key();
  const Cert identity = make_cert(identity_key.get(), {"rccx identity CA", ""}, nullptr,
                                  identity_key.get(), true, from, to);
  const Key permissions_key = new_p256_key();
  const Cert permissions = make_cert(permissions_key.get(), {"rccx permissions CA", ""}, nullptr,
                                     permissions_key.get(), true, from, to);
  const std::string governance =
      smime_signed(governance_xml(options.protection), permissions.get(), permissions_key.get());
  write_file(dir / kIdentityCaKey, pem_of(identity_key.get()), 0600);
  write_file(dir / kPermissionsCaKey, pem_of(permissions_key.get()), 0600);
  write_file(dir / kIdentityCa, pem_of(identity.get()), 0644);
  write_file(dir / kPermissionsCa, pem_of(permissions.get()), 0644);
  write_file(dir / "governance.p7s", governance, 0644);
}

void issue_participant(const fs::path& dir, const std::string& name,
                       const ParticipantOptions& options) {
  check_participant_name(name);
  if (name == "private") throw NetError("participant name 'private' is DIR's CA keys' directory");
  if (options.days < 1 || options.days > 36500) {
    throw NetError(fmt::format("validity {} days: give 1 .. 36500", options.days));
  }
  for (const char* f : {kIdentityCaKey, kPermissionsCaKey, kIdentityCa, kPermissionsCa}) {
    if (!fs::exists(dir / f)) {
      throw NetError(
          fmt::format("{} has no CA ({} is missing): run `rccx certs init {} "
                      "--participants {}` first",
                      dir.string(), (dir / f).string(), dir.string(), name));
    }
  }
  const Key identity_key = read_key(dir / kIdentityCaKey);
  const Cert identity = read_cert(dir / kIdentityCa);
  const Key permissions_key = read_key(dir / kPermissionsCaKey);
  const Cert permissions = read_cert(dir / kPermissionsCa);

  const Clock::time_point from = options.not_before.value_or(Clock::now() - std::chrono::hours(1));
  const Clock::time_point to =
      options.not_after.value_or(Clock::now() + std::chrono::hours(24) * options.days);
  const Role role = options.role.value_or(role_of(name));
  const Key key = new_p256_key();
  const Cert cert = make_cert(key.get(), {name, role == Role::program ? "program" : "serve"},
                              identity.get(), identity_key.get(), false, from, to);
  // The subject as Cyclone's authentication plugin gives it to access control (one line).
  char* oneline = X509_NAME_oneline(X509_get_subject_name(cert.get()), nullptr, 0);
  const std::string subject = must(oneline, "the certificate's subject");
  OPENSSL_free(oneline);
  const Grants grants =
      options.grants.value_or(role == Role::program ? program_grants() : serve_grants());
  const bool same = options.validity_of_certificate_only;
  const Clock::time_point p_from = same ? Clock::now() - std::chrono::hours(1) : from;
  const Clock::time_point p_to = same ? Clock::now() + std::chrono::hours(24) * options.days : to;
  const std::string signed_permissions = smime_signed(
      permissions_xml(subject, grants, p_from, p_to), permissions.get(), permissions_key.get());

  const fs::path own = dir / name;
  make_dir(own, 0755);
  write_file(own / "key.pem", pem_of(key.get()), 0600);
  write_file(own / "cert.pem", pem_of(cert.get()), 0644);
  write_file(own / "permissions.p7s", signed_permissions, 0644);
}

}  // namespace rccx::net
