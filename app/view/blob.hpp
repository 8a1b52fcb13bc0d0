#pragma once
// The viewer's binary messages: a JSON header followed by typed arrays, so rates and points travel
// as bytes, not as JSON numbers (docs/viewer.md#data).
// Takes: a JSON header and named arrays. Gives: one byte string,
//   "BVC3" | uint32 LE header length | header (JSON, space-padded to a multiple of 8) | arrays,
// each array starting at a multiple of 8 bytes, little-endian. The header gains "arrays": a list of
// {name, dtype (f32, f64, i32, u8), shape, offset (from the first array byte), bytes}.
#include <nlohmann/json.hpp>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace bvc3d::view {

struct BlobArray {
    std::string name;
    std::string dtype;  // f32, f64, i32, u8
    std::vector<std::size_t> shape;
    std::string bytes;
};

BlobArray f32_array(std::string name, std::span<const float> v, std::vector<std::size_t> shape = {});
BlobArray f32_array(std::string name, std::span<const double> v, std::vector<std::size_t> shape = {});  // narrowed
BlobArray f64_array(std::string name, std::span<const double> v, std::vector<std::size_t> shape = {});
BlobArray i32_array(std::string name, std::span<const std::int64_t> v, std::vector<std::size_t> shape = {});
BlobArray u8_array(std::string name, std::span<const std::uint8_t> v, std::vector<std::size_t> shape = {});

std::string encode_blob(nlohmann::json header, const std::vector<BlobArray>& arrays);

}  // namespace bvc3d::view
