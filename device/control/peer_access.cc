#include "device/control/peer_access.h"

#include <grp.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace px::device {
namespace {

std::string Who(const PeerCredentials& peer) {
  return "pid " + std::to_string(peer.pid) + " (uid " + std::to_string(peer.uid) + ", gid " + std::to_string(peer.gid) +
         ")";
}

std::string Allowed(const ControlAccess& access) {
  std::string text = "only uid " + std::to_string(access.owner_uid) + ", root";
  if (access.group) text += " and group " + std::to_string(*access.group);
  return text;
}

}  // namespace

ControlAccess OwnerAccess(std::optional<gid_t> group) { return ControlAccess{::geteuid(), group}; }

StatusOr<PeerCredentials> ReadPeerCredentials(int fd) {
  ucred cred{};
  socklen_t length = sizeof(cred);
  if (::getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &cred, &length) != 0) {
    return InternalError(std::string("control socket: SO_PEERCRED: ") + std::strerror(errno));
  }
  PeerCredentials peer;
  peer.pid = cred.pid;
  peer.uid = cred.uid;
  peer.gid = cred.gid;
#ifdef SO_PEERGROUPS
  // Linux >= 4.13. Ask with a small buffer first; ERANGE tells the size needed.
  std::vector<gid_t> groups(16);
  socklen_t bytes = static_cast<socklen_t>(groups.size() * sizeof(gid_t));
  int result = ::getsockopt(fd, SOL_SOCKET, SO_PEERGROUPS, groups.data(), &bytes);
  if (result != 0 && errno == ERANGE) {
    groups.resize(bytes / sizeof(gid_t) + 1);
    bytes = static_cast<socklen_t>(groups.size() * sizeof(gid_t));
    result = ::getsockopt(fd, SOL_SOCKET, SO_PEERGROUPS, groups.data(), &bytes);
  }
  if (result == 0) {
    groups.resize(bytes / sizeof(gid_t));
    peer.groups = std::move(groups);
  }
#endif
  return peer;
}

Status CheckPeer(const PeerCredentials& peer, const ControlAccess& access) {
  if (peer.uid == access.owner_uid || peer.uid == 0) return OkStatus();
  if (access.group) {
    const gid_t group = *access.group;
    if (peer.gid == group || std::find(peer.groups.begin(), peer.groups.end(), group) != peer.groups.end()) {
      return OkStatus();
    }
  }
  return PermissionDeniedError(Who(peer) + " may not use the control socket: " + Allowed(access));
}

StatusOr<gid_t> ResolveGroup(const std::string& name_or_gid, const std::string& field) {
  if (name_or_gid.empty()) return InvalidArgumentError(field + ": empty");
  if (std::all_of(name_or_gid.begin(), name_or_gid.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    if (name_or_gid.size() > 9) return InvalidArgumentError(field + ": gid " + name_or_gid + " is too large");
    return static_cast<gid_t>(std::stoul(name_or_gid));
  }
  std::vector<char> buffer(4096);
  group entry{};
  group* found = nullptr;
  int err = 0;
  while ((err = ::getgrnam_r(name_or_gid.c_str(), &entry, buffer.data(), buffer.size(), &found)) == ERANGE &&
         buffer.size() < (1u << 20)) {
    buffer.resize(buffer.size() * 2);
  }
  if (err != 0) {
    return UnavailableError(field + ": looking up '" + name_or_gid + "': " + std::strerror(err));
  }
  if (found == nullptr) return NotFoundError(field + ": '" + name_or_gid + "': no such group");
  return found->gr_gid;
}

Status RestrictSocketFile(const std::filesystem::path& path, const ControlAccess& access) {
  if (access.group && ::chown(path.c_str(), static_cast<uid_t>(-1), *access.group) != 0) {
    const int err = errno;
    return PermissionDeniedError("control socket " + path.string() + ": cannot give it to group " +
                                 std::to_string(*access.group) + " (control.group): " + std::strerror(err) +
                                 (err == EPERM ? "; the daemon's user must be a member of that group" : ""));
  }
  const mode_t mode = access.group ? 0660 : 0600;
  if (::chmod(path.c_str(), mode) != 0) {
    return InternalError("control socket " + path.string() + ": chmod: " + std::strerror(errno));
  }
  return OkStatus();
}

}  // namespace px::device
