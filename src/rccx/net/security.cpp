#include "rccx/net/security.hpp"

#include <dlfcn.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "rccx/net/certs.hpp"

namespace rccx::net {

namespace fs = std::filesystem;

namespace {

/// The directories where Cyclone's security plugins may be, in order: $RCCX_DDS_SECURITY_DIR
/// when set; beside the libddsc this process loaded, in its Debian subdirectory
/// (libddsc0debian/) and then in the same directory (upstream's install).
std::vector<fs::path> plugin_dirs() {
  std::vector<fs::path> dirs;
  if (const char* env = std::getenv("RCCX_DDS_SECURITY_DIR"); env != nullptr && *env != '\0') {
    dirs.emplace_back(env);
  }
  Dl_info info{};
  // Any function of libddsc tells where the library was loaded from.
  if (dladdr(reinterpret_cast<void*>(&dds_create_participant), &info) != 0 &&
      info.dli_fname != nullptr) {
    std::error_code ec;
    fs::path lib = fs::canonical(info.dli_fname, ec);
    if (ec) lib = info.dli_fname;
    dirs.push_back(lib.parent_path() / "libddsc0debian");
    dirs.push_back(lib.parent_path());
  }
  dirs.emplace_back("/usr/lib/x86_64-linux-gnu/libddsc0debian");
  return dirs;
}

/// The directory holding all three plugins; throws NetError naming where it looked.
fs::path plugin_dir() {
  const std::vector<fs::path> dirs = plugin_dirs();
  for (const fs::path& d : dirs) {
    bool all = true;
    for (const char* lib :
         {"libdds_security_auth.so", "libdds_security_crypto.so", "libdds_security_ac.so"}) {
      all = all && access((d / lib).c_str(), R_OK) == 0;
    }
    if (all) return d;
  }
  std::string looked;
  for (const fs::path& d : dirs) looked += (looked.empty() ? "" : ", ") + d.string();
  throw NetError(fmt::format(
      "--secure: Cyclone DDS's security plugins (libdds_security_auth.so, "
      "libdds_security_crypto.so, libdds_security_ac.so) are not in {}: install Debian's "
      "libddsc0debian (scripts/install-deps), or set RCCX_DDS_SECURITY_DIR to their directory",
      looked));
}

/// "file:<absolute path>" of `name` in `dir`, which must be a readable file.
std::string file_uri(const fs::path& dir, const std::string& name, const NetOptions& o) {
  std::error_code ec;
  const fs::path path = fs::absolute(dir / name, ec);
  if (ec || !fs::is_regular_file(path, ec) || access(path.c_str(), R_OK) != 0) {
    throw NetError(fmt::format(
        "--secure {}: {} is missing or unreadable; run `rccx certs init {} --participants {}` "
        "(or `rccx certs add {} --participant {}` for a CA made already)",
        o.secure_dir.string(), (dir / name).string(), o.secure_dir.string(),
        o.secure_identity.empty() ? "NAME" : o.secure_identity, o.secure_dir.string(),
        o.secure_identity.empty() ? "NAME" : o.secure_identity));
  }
  return "file:" + path.string();
}

}  // namespace

void add_security_properties(dds_qos_t* qos, const NetOptions& options) {
  if (options.secure_identity.empty()) {
    throw NetError(fmt::format(
        "--secure {}: say which participant this is (--identity NAME: a directory of {} made by "
        "rccx certs init)",
        options.secure_dir.string(), options.secure_dir.string()));
  }
  try {
    check_participant_name(options.secure_identity);
  } catch (const NetError& e) {
    throw NetError(fmt::format("--identity: {}", e.what()));
  }
  // Cyclone's access control reads domain ids 0 .. 230 only (its governance and permissions
  // parser); the documents of rccx certs cover exactly those.
  if (const std::uint32_t domain = domain_of(options); domain > kMaxSecureDomain) {
    throw NetError(
        fmt::format("--secure: DDS domain {} is out of range for DDS Security: give 0 .. {}",
                    domain, kMaxSecureDomain));
  }
  const fs::path& dir = options.secure_dir;
  const fs::path own = dir / options.secure_identity;
  // Every file checked before any property is set: a bad directory changes nothing.
  const std::string identity_ca = file_uri(dir, "identity_ca.pem", options);
  const std::string permissions_ca = file_uri(dir, "permissions_ca.pem", options);
  const std::string governance = file_uri(dir, "governance.p7s", options);
  const std::string cert = file_uri(own, "cert.pem", options);
  const std::string key = file_uri(own, "key.pem", options);
  const std::string permissions = file_uri(own, "permissions.p7s", options);
  const fs::path plugins = plugin_dir();

  dds_qset_prop(qos, "dds.sec.auth.library.path", (plugins / "libdds_security_auth.so").c_str());
  dds_qset_prop(qos, "dds.sec.auth.library.init", "init_authentication");
  dds_qset_prop(qos, "dds.sec.auth.library.finalize", "finalize_authentication");
  dds_qset_prop(qos, "dds.sec.crypto.library.path",
                (plugins / "libdds_security_crypto.so").c_str());
  dds_qset_prop(qos, "dds.sec.crypto.library.init", "init_crypto");
  dds_qset_prop(qos, "dds.sec.crypto.library.finalize", "finalize_crypto");
  dds_qset_prop(qos, "dds.sec.access.library.path", (plugins / "libdds_security_ac.so").c_str());
  dds_qset_prop(qos, "dds.sec.access.library.init", "init_access_control");
  dds_qset_prop(qos, "dds.sec.access.library.finalize", "finalize_access_control");

  dds_qset_prop(qos, "dds.sec.auth.identity_ca", identity_ca.c_str());
  dds_qset_prop(qos, "dds.sec.auth.identity_certificate", cert.c_str());
  dds_qset_prop(qos, "dds.sec.auth.private_key", key.c_str());
  dds_qset_prop(qos, "dds.sec.access.permissions_ca", permissions_ca.c_str());
  dds_qset_prop(qos, "dds.sec.access.governance", governance.c_str());
  dds_qset_prop(qos, "dds.sec.access.permissions", permissions.c_str());
}

}  // namespace rccx::net
