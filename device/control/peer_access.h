// Who may use the control socket: the daemon's own user, root, and, when control.group is set,
// members of that group. The kernel enforces it first through the socket file's mode (0600, or
// 0660 and owned by the group); the daemon checks every connection's peer credentials too
// (SO_PEERCRED, SO_PEERGROUPS), so a socket whose mode was loosened by hand, or a connection
// handed on by another process, is still refused with a logged reason.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/core/status.h"

namespace px::device {

struct ControlAccess {
  uid_t owner_uid = 0;         // the daemon's effective uid
  std::optional<gid_t> group;  // members may connect too; nullopt: the owner (and root) only
};

// The daemon's own access rule: its effective uid, and `group` (already resolved).
ControlAccess OwnerAccess(std::optional<gid_t> group = std::nullopt);

struct PeerCredentials {
  pid_t pid = 0;
  uid_t uid = 0;
  gid_t gid = 0;
  std::vector<gid_t> groups;  // supplementary groups (SO_PEERGROUPS; empty where unsupported)
};

// The credentials of the process at the other end of a connected Unix socket.
StatusOr<PeerCredentials> ReadPeerCredentials(int fd);

// OK, or PERMISSION_DENIED naming the peer and who may connect:
//   "pid 4242 (uid 65534, gid 65534) may not use the control socket: only uid 0, root and group 1000"
Status CheckPeer(const PeerCredentials& peer, const ControlAccess& access);

// "parallax" or "1234" -> a gid. NOT_FOUND names the group; INVALID_ARGUMENT for an empty or
// malformed name.
StatusOr<gid_t> ResolveGroup(const std::string& name_or_gid, const std::string& field = "control.group");

// Call after bind() and before listen(): mode 0600, or 0660 with the file's group set to
// access.group. Errors name the socket and the group.
Status RestrictSocketFile(const std::filesystem::path& path, const ControlAccess& access);

}  // namespace px::device
