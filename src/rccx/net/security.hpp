// DDS Security for rccx's participants (docs/NETWORK.md, "Security"): the files `rccx certs
// init DIR --participants a,b,...` makes, and the participant QoS properties that switch
// Cyclone's security plugins on with them.
#pragma once

#include <dds/dds.h>

#include "rccx/net/topics.hpp"

namespace rccx::net {

/// Sets the DDS Security properties (identity CA, certificate, private key, permissions CA,
/// governance, permissions; the plugins' libraries) of participant `options.secure_identity`
/// from `options.secure_dir` on `qos`. Throws NetError naming a missing or unreadable file and
/// what to run.
void add_security_properties(dds_qos_t* qos, const NetOptions& options);

}  // namespace rccx::net
