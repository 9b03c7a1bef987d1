// Explicit instantiations of the frame codecs for both firmware scalars (MCU object checks).
#include "jointguard/protocol/frames.hpp"

namespace jg::protocol {
template std::uint8_t encode_outward<float>(const OutwardMessage<float>&, std::uint8_t, std::uint8_t*) noexcept;
template std::uint8_t encode_outward<q16>(const OutwardMessage<q16>&, std::uint8_t, std::uint8_t*) noexcept;
template FrameError decode_outward<float>(const std::uint8_t*, std::uint8_t, OutwardMessage<float>&, std::uint8_t&) noexcept;
template FrameError decode_outward<q16>(const std::uint8_t*, std::uint8_t, OutwardMessage<q16>&, std::uint8_t&) noexcept;
template std::uint8_t encode_inward<float>(const InwardMessage<float>&, std::uint8_t, std::uint8_t*) noexcept;
template std::uint8_t encode_inward<q16>(const InwardMessage<q16>&, std::uint8_t, std::uint8_t*) noexcept;
template FrameError decode_inward<float>(const std::uint8_t*, std::uint8_t, InwardMessage<float>&, std::uint8_t&) noexcept;
template FrameError decode_inward<q16>(const std::uint8_t*, std::uint8_t, InwardMessage<q16>&, std::uint8_t&) noexcept;
}  // namespace jg::protocol
