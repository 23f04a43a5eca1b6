#include "splat/spz.h"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>

#include "splat/atomic_file.h"
#include "splat/error.h"

namespace splat {

namespace {

constexpr uint32_t kMagic = 0x5053474e;  // "NGSP"
constexpr uint32_t kVersion = 2;
constexpr size_t kHeaderBytes = 16;
constexpr int kShCoefficients = 15;  // degree 3, besides the DC term
// The DC colour's scale and the SH precision of the reference encoder.
constexpr float kColorScale = 0.15f;
constexpr int kSh1Bits = 5, kShRestBits = 4;

uint8_t to_byte(float x) { return uint8_t(std::clamp(std::lround(x), 0l, 255l)); }

// A coefficient to 8 bits with the low bits zeroed (they compress better).
uint8_t quantize_sh(float x, int bits) {
  const int bucket = 1 << (8 - bits);
  const long q = std::lround(x * 128.f) + 128;
  return uint8_t(std::clamp((q + bucket / 2) / bucket * bucket, 0l, 255l));
}

// The most fractional bits (at most 12) with which every coordinate fits
// 24 signed bits.
int fractional_bits_for(const std::vector<float>& means) {
  float extent = 1.f;
  for (float v : means)
    if (std::isfinite(v)) extent = std::max(extent, std::abs(v));
  return std::clamp(22 - int(std::ceil(std::log2(extent))), 0, 12);
}

void append_u32(std::string& s, uint32_t v) {
  for (int k = 0; k < 4; ++k) s.push_back(char((v >> (8 * k)) & 0xff));
}

std::string gzip(const std::string& raw) {
  z_stream z{};
  // 15 + 16: a gzip header and trailer around the deflate stream.
  if (deflateInit2(&z, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK)
    throw std::runtime_error("zlib: deflateInit2 failed");
  std::string out(deflateBound(&z, uLong(raw.size())), '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(raw.data()));
  z.avail_in = uInt(raw.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = uInt(out.size());
  const int rc = deflate(&z, Z_FINISH);
  out.resize(z.total_out);
  deflateEnd(&z);
  if (rc != Z_STREAM_END) throw std::runtime_error("zlib: deflate did not finish");
  return out;
}

std::string gunzip(const std::filesystem::path& file, const std::string& packed) {
  z_stream z{};
  if (inflateInit2(&z, 15 + 32) != Z_OK) throw InputError(file, "zlib: inflateInit2 failed");
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(packed.data()));
  z.avail_in = uInt(packed.size());
  std::string out;
  char chunk[1 << 16];
  int rc = Z_OK;
  while (rc != Z_STREAM_END) {
    z.next_out = reinterpret_cast<Bytef*>(chunk);
    z.avail_out = sizeof(chunk);
    rc = inflate(&z, Z_NO_FLUSH);
    if (rc != Z_OK && rc != Z_STREAM_END) {
      inflateEnd(&z);
      throw InputError(file, "not a gzip stream or truncated (SPZ is gzip-compressed)");
    }
    out.append(chunk, sizeof(chunk) - z.avail_out);
    if (rc == Z_OK && z.avail_in == 0 && z.avail_out != 0) {
      inflateEnd(&z);
      throw InputError(file, "truncated gzip stream");
    }
  }
  inflateEnd(&z);
  return out;
}

}  // namespace

std::string encode_spz(const GaussianModel& m) {
  const size_t n = m.size();
  const int bits = fractional_bits_for(m.means);
  std::string raw;
  raw.reserve(kHeaderBytes + n * (9 + 1 + 3 + 3 + 3 + 3 * kShCoefficients));
  append_u32(raw, kMagic);
  append_u32(raw, kVersion);
  append_u32(raw, uint32_t(n));
  raw.push_back(char(3));  // SH degree
  raw.push_back(char(bits));
  raw.push_back(char(0));  // flags: not trained with antialiasing
  raw.push_back(char(0));
  const float scale = float(1 << bits);
  for (float v : m.means) {
    const int32_t q = int32_t(std::clamp(std::lround(v * scale), -(1l << 23), (1l << 23) - 1));
    for (int k = 0; k < 3; ++k) raw.push_back(char((q >> (8 * k)) & 0xff));
  }
  for (float logit : m.opacity_logits) raw.push_back(char(to_byte(sigmoid(logit) * 255.f)));
  for (float c : m.sh_dc) raw.push_back(char(to_byte(c * kColorScale * 255.f + 127.5f)));
  for (float s : m.log_scales) raw.push_back(char(to_byte((s + 10.f) * 16.f)));
  for (size_t i = 0; i < n; ++i) {
    const float* q = &m.rotations[4 * i];  // w x y z
    const float norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    // q and -q are one rotation: store the one with w >= 0, whose w follows.
    const float sign = (q[0] < 0 ? -1.f : 1.f) / (norm > 0 ? norm : 1.f);
    for (int k = 1; k <= 3; ++k) raw.push_back(char(to_byte(q[k] * sign * 127.5f + 127.5f)));
  }
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3 * kShCoefficients; ++c)
      raw.push_back(char(
          quantize_sh(m.sh_rest[3 * kShCoefficients * i + c], c < 9 ? kSh1Bits : kShRestBits)));
  return gzip(raw);
}

void write_spz(const std::filesystem::path& file, const GaussianModel& model) {
  const std::string bytes = encode_spz(model);
  write_atomically(file, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    out.close();
    if (!out) throw_write_error(file);
  });
}

GaussianModel read_spz(const std::filesystem::path& file) {
  const std::string raw = gunzip(file, read_text_file(file));
  if (raw.size() < kHeaderBytes) throw InputError(file, "shorter than the SPZ header");
  const auto u8 = [&](size_t at) { return uint8_t(raw[at]); };
  const auto u32 = [&](size_t at) {
    return uint32_t(u8(at)) | uint32_t(u8(at + 1)) << 8 | uint32_t(u8(at + 2)) << 16 |
           uint32_t(u8(at + 3)) << 24;
  };
  if (u32(0) != kMagic) throw InputError(file, "not an SPZ file (wrong magic number)");
  if (u32(4) != kVersion)
    throw InputError(file, "SPZ version " + std::to_string(u32(4)) + " (only 2 is read)");
  const size_t n = u32(8);
  const int degree = u8(12), bits = u8(13);
  if (degree > 3) throw InputError(file, "SH degree " + std::to_string(degree) + " above 3");
  if (bits > 23) throw InputError(file, "fractional bits " + std::to_string(bits) + " above 23");
  const int sh = (degree + 1) * (degree + 1) - 1;
  const size_t per_gaussian = 9 + 1 + 3 + 3 + 3 + 3 * size_t(sh);
  if (raw.size() - kHeaderBytes != n * per_gaussian)
    throw InputError(file, "holds " + std::to_string(raw.size() - kHeaderBytes) +
                               " bytes of data, not the " + std::to_string(n * per_gaussian) +
                               " of " + std::to_string(n) + " Gaussians");
  GaussianModel m;
  m.resize(n);
  size_t at = kHeaderBytes;
  const float step = 1.f / float(1 << bits);
  for (size_t k = 0; k < 3 * n; ++k, at += 3) {
    int32_t q = int32_t(u8(at)) | int32_t(u8(at + 1)) << 8 | int32_t(u8(at + 2)) << 16;
    if (q & 0x800000) q -= 1 << 24;
    m.means[k] = float(q) * step;
  }
  for (size_t i = 0; i < n; ++i, ++at) {
    const float a = std::clamp(u8(at) / 255.f, 1e-6f, 1.f - 1e-6f);
    m.opacity_logits[i] = std::log(a / (1.f - a));
  }
  for (size_t k = 0; k < 3 * n; ++k, ++at) m.sh_dc[k] = (u8(at) / 255.f - 0.5f) / kColorScale;
  for (size_t k = 0; k < 3 * n; ++k, ++at) m.log_scales[k] = u8(at) / 16.f - 10.f;
  for (size_t i = 0; i < n; ++i, at += 3) {
    float* q = &m.rotations[4 * i];
    for (int k = 0; k < 3; ++k) q[k + 1] = u8(at + k) / 127.5f - 1.f;
    q[0] = std::sqrt(std::max(0.f, 1.f - q[1] * q[1] - q[2] * q[2] - q[3] * q[3]));
  }
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3 * sh; ++c, ++at)
      m.sh_rest[3 * kShCoefficients * i + c] = (u8(at) - 128.f) / 128.f;
  return m;
}

}  // namespace splat
