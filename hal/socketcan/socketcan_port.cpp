// The only file that includes Linux's CAN headers (convention: one CAN interface, several
// backends; platform headers stay inside their backend's source).
#include "jointguard/hal/socketcan.hpp"

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <linux/net_tstamp.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/uio.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <stdexcept>
#include <vector>

namespace jg::hal {
namespace {

[[noreturn]] void fail(const std::string& interface, const std::string& what, int err) {
  throw std::runtime_error("socketcan " + interface + ": " + what + ": " + std::strerror(err));
}

std::uint64_t to_us(const timespec& ts) {
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000000ULL + static_cast<std::uint64_t>(ts.tv_nsec) / 1000ULL;
}

}  // namespace

SocketCanPort::SocketCanPort(const std::string& interface, SocketCanOptions options) : interface_(interface), options_(options) {
  if (interface.empty() || interface.size() >= IFNAMSIZ) {
    throw std::runtime_error("socketcan: interface name '" + interface + "' must have 1.." + std::to_string(IFNAMSIZ - 1) + " characters");
  }
  fd_ = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd_ < 0) { fail(interface, "cannot open a raw CAN socket (is the kernel's can-raw module loaded?)", errno);
}
  const unsigned index = ::if_nametoindex(interface.c_str());
  if (index == 0) {
    const int err = errno;
    ::close(fd_);
    fail(interface, "no such interface (create it: ip link add dev " + interface + " type vcan && ip link set up " + interface + ")", err);
  }
  auto set = [&](int level, int name, const void* value, socklen_t size, const char* what) {
    if (::setsockopt(fd_, level, name, value, size) != 0) {
      const int err = errno;
      ::close(fd_);
      fail(interface, what, err);
    }
  };
  const int on = 1;
  if (options.fd) { set(SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof on, "CAN FD frames not supported");
}
  const int own = options.receive_own ? 1 : 0;
  set(SOL_CAN_RAW, CAN_RAW_RECV_OWN_MSGS, &own, sizeof own, "cannot set CAN_RAW_RECV_OWN_MSGS");
  const can_err_mask_t errors = CAN_ERR_BUSOFF | CAN_ERR_CRTL | CAN_ERR_RESTARTED;
  set(SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &errors, sizeof errors, "cannot subscribe to error frames");
  // Hardware receive timestamps where the adapter has them, the kernel's otherwise.
  const int stamping = SOF_TIMESTAMPING_RX_HARDWARE | SOF_TIMESTAMPING_RAW_HARDWARE | SOF_TIMESTAMPING_RX_SOFTWARE |
                       SOF_TIMESTAMPING_SOFTWARE;
  if (::setsockopt(fd_, SOL_SOCKET, SO_TIMESTAMPING, &stamping, sizeof stamping) != 0) {
    set(SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on, "no receive timestamps");
  }
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = static_cast<int>(index);
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    const int err = errno;
    ::close(fd_);
    fail(interface, "cannot bind", err);
  }
  if (options.fd) {
    ifreq ifr{};
    std::strncpy(static_cast<char*>(ifr.ifr_name), interface.c_str(), IFNAMSIZ - 1);
    // NOLINTNEXTLINE(cppcoreguidelines-pro-type-vararg,hicpp-vararg): ioctl is the kernel's only way to read the MTU
    if (::ioctl(fd_, SIOCGIFMTU, &ifr) == 0 && ifr.ifr_mtu != CANFD_MTU) {
      ::close(fd_);
      throw std::runtime_error("socketcan " + interface + ": not CAN FD capable (MTU " + std::to_string(ifr.ifr_mtu) +
                               "); set it with: ip link set " + interface + " mtu 72");
    }
  }
}

SocketCanPort::~SocketCanPort() {
  if (fd_ >= 0) { ::close(fd_);
}
}

SocketCanPort::SocketCanPort(SocketCanPort&& other) noexcept
    : fd_(other.fd_), interface_(std::move(other.interface_)), options_(other.options_), state_(other.state_), counters_(other.counters_) {
  other.fd_ = -1;
}

CanStatus SocketCanPort::send(const CanFrame& f) noexcept {
  if (!valid_length(f.length, f.fd) || f.id > (f.extended ? CAN_EFF_MASK : CAN_SFF_MASK) || (f.fd && !options_.fd)) {
    return CanStatus::invalid;
  }
  // A controller bus-off (error frame) refuses sends until it is restarted; the interface
  // merely being down (ENETDOWN below) does not: the next write tells whether it is up again.
  if (state_ == CanErrorState::bus_off && !link_down_) { return CanStatus::bus_off;
}
  canfd_frame out{};
  out.can_id = f.id | (f.extended ? CAN_EFF_FLAG : 0U);
  out.len = f.length;
  out.flags = f.fd ? static_cast<__u8>(CANFD_BRS) : static_cast<__u8>(0U);
  std::memcpy(static_cast<__u8*>(out.data), static_cast<const std::uint8_t*>(f.data), f.length);
  const std::size_t size = f.fd ? CANFD_MTU : CAN_MTU;  // a classic frame is written as struct can_frame
  const ssize_t n = ::write(fd_, &out, size);
  if (n == static_cast<ssize_t>(size)) {
    if (link_down_) {  // the interface is up again
      link_down_ = false;
      state_ = CanErrorState::error_active;
    }
    return CanStatus::ok;
}
  if (n < 0 && (errno == ENOBUFS || errno == EAGAIN)) { return CanStatus::queue_full;
}
  ++counters_.send_errors;
  if (n < 0 && errno == ENETDOWN) {
    state_ = CanErrorState::bus_off;
    link_down_ = true;
}
  return n < 0 && errno == ENETDOWN ? CanStatus::bus_off : CanStatus::invalid;
}

bool SocketCanPort::receive(CanFrame& out) noexcept {
  while (true) {
    canfd_frame in{};
    iovec iov{&in, sizeof in};
    alignas(cmsghdr) std::array<char, CMSG_SPACE(sizeof(timespec) * 3) + CMSG_SPACE(sizeof(timespec))> control{};
    msghdr msg{};
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    msg.msg_control = control.data();
    msg.msg_controllen = control.size();
    const ssize_t n = ::recvmsg(fd_, &msg, MSG_DONTWAIT);
    if (n < 0) { return false;  // EAGAIN: nothing queued (other errors: nothing readable either)
}
    const bool fd_frame = n == static_cast<ssize_t>(CANFD_MTU);
    if (!fd_frame && n != static_cast<ssize_t>(CAN_MTU)) { continue;  // not a CAN frame: skip
}
    if ((in.can_id & CAN_ERR_FLAG) != 0U) {
      on_error_frame(in.can_id, static_cast<const std::uint8_t*>(in.data));
      continue;
    }
    if ((in.can_id & CAN_RTR_FLAG) != 0U) { continue;  // the protocol has no remote frames
}
    out = CanFrame{};
    out.extended = (in.can_id & CAN_EFF_FLAG) != 0U;
    out.id = in.can_id & (out.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
    out.fd = fd_frame;
    out.length = in.len > (fd_frame ? CANFD_MAX_DLEN : CAN_MAX_DLEN) ? static_cast<std::uint8_t>(fd_frame ? CANFD_MAX_DLEN : CAN_MAX_DLEN)
                                                                     : in.len;
    std::memcpy(static_cast<std::uint8_t*>(out.data), static_cast<const __u8*>(in.data), out.length);
    for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
      if (c->cmsg_level != SOL_SOCKET) { continue;
}
      if (c->cmsg_type == SO_TIMESTAMPING) {
        std::array<timespec, 3> ts{};
        std::memcpy(ts.data(), CMSG_DATA(c), sizeof ts);
        out.timestamp_us = (ts[2].tv_sec != 0 || ts[2].tv_nsec != 0) ? to_us(ts[2]) : to_us(ts[0]);
      } else if (c->cmsg_type == SO_TIMESTAMPNS) {
        timespec ts{};
        std::memcpy(&ts, CMSG_DATA(c), sizeof ts);
        out.timestamp_us = to_us(ts);
      }
    }
    return true;
  }
}

void SocketCanPort::on_error_frame(std::uint32_t can_id, const std::uint8_t* data) noexcept {
  ++counters_.error_frames;
  if ((can_id & CAN_ERR_BUSOFF) != 0U) {
    state_ = CanErrorState::bus_off;
    link_down_ = false;  // the controller's bus-off latches until its restart
  } else if ((can_id & CAN_ERR_RESTARTED) != 0U) {
    state_ = CanErrorState::error_active;
  } else if ((can_id & CAN_ERR_CRTL) != 0U) {
    const auto ctrl = data[1];
    if ((ctrl & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) != 0U) { state_ = CanErrorState::error_passive;
}
#ifdef CAN_ERR_CRTL_ACTIVE
    if ((ctrl & CAN_ERR_CRTL_ACTIVE) != 0U) { state_ = CanErrorState::error_active;
}
#endif
  }
}

void SocketCanPort::inject_controller_state(CanErrorState state) noexcept {
  std::array<std::uint8_t, CAN_ERR_DLC> data{};
  switch (state) {
    case CanErrorState::bus_off: on_error_frame(CAN_ERR_FLAG | CAN_ERR_BUSOFF, data.data()); break;
    case CanErrorState::error_active: on_error_frame(CAN_ERR_FLAG | CAN_ERR_RESTARTED, data.data()); break;
    case CanErrorState::error_passive:
      data[1] = CAN_ERR_CRTL_TX_PASSIVE;
      on_error_frame(CAN_ERR_FLAG | CAN_ERR_CRTL, data.data());
      break;
  }
}

void SocketCanPort::set_filters(const CanFilter* filters, std::size_t n) const noexcept {
  std::vector<can_filter> k;
  k.reserve(n == 0 ? 1 : n);
  for (std::size_t i = 0; i < n; ++i) {
    const bool standard = filters[i].match <= CAN_SFF_MASK && filters[i].mask <= CAN_SFF_MASK;
    const canid_t frame_type = standard ? 0U : CAN_EFF_FLAG;
    k.push_back({filters[i].match | frame_type, filters[i].mask | CAN_EFF_FLAG | CAN_RTR_FLAG});
  }
  if (n == 0) { k.push_back({0U, 0U});  // accept everything
}
  (void)::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FILTER, k.data(), static_cast<socklen_t>(k.size() * sizeof(can_filter)));
}

bool SocketCanPort::wait_readable(std::int64_t timeout_us) const noexcept {
  pollfd p{fd_, POLLIN, 0};
  const int ms = timeout_us < 0 ? -1 : static_cast<int>((timeout_us + 999) / 1000);
  return ::poll(&p, 1, ms) > 0 && (p.revents & POLLIN) != 0;
}

// NOLINTNEXTLINE(readability-convert-member-functions-to-static): the clock contract is a const member
std::uint64_t MonotonicClock::now_us() const noexcept {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return to_us(ts);
}

}  // namespace jg::hal
