#include "view/blob.hpp"

#include <bit>
#include <cstring>
#include <stdexcept>

namespace bvc3d::view {

static_assert(std::endian::native == std::endian::little, "the viewer's arrays are little-endian");

namespace {

template <class T>
BlobArray make(std::string name, const char* dtype, std::span<const T> v, std::vector<std::size_t> shape) {
    if (shape.empty()) shape = {v.size()};
    std::size_t n = 1;
    for (auto d : shape) n *= d;
    if (n != v.size()) throw std::logic_error("blob array '" + name + "': shape does not match its length");
    BlobArray a{std::move(name), dtype, std::move(shape), std::string(v.size() * sizeof(T), '\0')};
    if (!v.empty()) std::memcpy(a.bytes.data(), v.data(), a.bytes.size());
    return a;
}

}  // namespace

BlobArray f32_array(std::string name, std::span<const float> v, std::vector<std::size_t> shape) {
    return make(std::move(name), "f32", v, std::move(shape));
}
BlobArray f32_array(std::string name, std::span<const double> v, std::vector<std::size_t> shape) {
    const std::vector<float> narrow(v.begin(), v.end());
    return make<float>(std::move(name), "f32", narrow, std::move(shape));
}
BlobArray f64_array(std::string name, std::span<const double> v, std::vector<std::size_t> shape) {
    return make(std::move(name), "f64", v, std::move(shape));
}
BlobArray i32_array(std::string name, std::span<const std::int64_t> v, std::vector<std::size_t> shape) {
    const std::vector<std::int32_t> narrow(v.begin(), v.end());
    return make<std::int32_t>(std::move(name), "i32", narrow, std::move(shape));
}
BlobArray u8_array(std::string name, std::span<const std::uint8_t> v, std::vector<std::size_t> shape) {
    return make(std::move(name), "u8", v, std::move(shape));
}

std::string encode_blob(nlohmann::json header, const std::vector<BlobArray>& arrays) {
    auto padded = [](std::size_t n) { return (n + 7) / 8 * 8; };
    header["arrays"] = nlohmann::json::array();
    std::size_t offset = 0;
    for (const auto& a : arrays) {
        header["arrays"].push_back(
            {{"name", a.name}, {"dtype", a.dtype}, {"shape", a.shape}, {"offset", offset}, {"bytes", a.bytes.size()}});
        offset += padded(a.bytes.size());
    }
    std::string text = header.dump();
    text.resize(padded(text.size()), ' ');
    const auto length = static_cast<std::uint32_t>(text.size());
    std::string out = "BVC3";
    out.append(reinterpret_cast<const char*>(&length), 4);
    out += text;
    for (const auto& a : arrays) {
        out += a.bytes;
        out.resize(padded(out.size() - 8 - text.size()) + 8 + text.size(), '\0');
    }
    return out;
}

}  // namespace bvc3d::view
