// The light-map encodings: png8's range at a percentile, sRGB coding and the error measure the docs quote, and
// every encoding's encode → decode round trip within its stated tolerance.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <gtest/gtest.h>

#include "common/error.h"
#include "export/map_encoding.h"
#include "scene/image_codec.h"

using namespace irbake;

namespace {

// 1000 covered texels whose value falls geometrically from 2 to 2e-3 (three decades, like a room lit
// by one lamp), plus one hot texel at 50 and one uncovered texel at 1000 (ignored).
Lightmap decades() {
  Lightmap m;
  m.width = 1002;
  m.height = 1;
  for (int i = 0; i < 1000; ++i) {
    const float v = 2.0f * std::pow(1e-3f, i / 999.0f);
    m.texels.push_back(glm::vec3(v, 0.5f * v, 0.25f * v));
    m.valid.push_back(1);
  }
  m.texels.push_back(glm::vec3(50.0f));
  m.valid.push_back(1);
  m.texels.push_back(glm::vec3(1000.0f));
  m.valid.push_back(0);
  return m;
}

const MapEncoding& png8() { return mapEncoding(MapEncodingKind::Png8); }

MapEncodeOptions png8Options(bool srgb, double percentile) {
  MapEncodeOptions o;
  o.srgb = srgb;
  o.percentile = percentile;
  return o;
}

}  // namespace

TEST(MapEncodingPng8, RangeIsTheCoveredPercentile) {
  const Lightmap m = decades();
  // Maximum of the covered texels: the hot texel, not the uncovered 1000.
  EXPECT_FLOAT_EQ(png8().encode(m, png8Options(true, 100.0)).metadata.intensity, 50.0f);
  // 1001 covered texels: the 99.9th percentile (nearest rank 1000) is the brightest of the ramp, 2.
  EXPECT_FLOAT_EQ(png8().encode(m, png8Options(true, 99.9)).metadata.intensity, 2.0f);
  // The median (nearest rank 501 from the darkest): ramp texel 999 − 500 = 499.
  EXPECT_FLOAT_EQ(png8().encode(m, png8Options(true, 50.0)).metadata.intensity, 2.0f * std::pow(1e-3f, 499 / 999.0f));
}

TEST(MapEncodingPng8, SrgbCodesDecodeWithinHalfAStep) {
  const Lightmap m = decades();
  const EncodedMap png = png8().encode(m, {});
  const Texture back = decodeImageToTexture(png.bytes.data(), png.bytes.size(), true, "lightmap");
  ASSERT_EQ(back.width, 1002);
  for (int i = 0; i < 1000; ++i)
    for (int c = 0; c < 3; ++c) {
      const float v = m.texels[i][c] / png.metadata.intensity;
      const float s = linearToSrgb(v);
      // The decoded value lies between the decodes of the code's half-step neighbours.
      EXPECT_GE(back.texels[i][c], srgbToLinear(std::max(0.0f, s - 0.5f / 255.0f)) - 1e-6f) << i;
      EXPECT_LE(back.texels[i][c], srgbToLinear(std::min(1.0f, s + 0.5f / 255.0f)) + 1e-6f) << i;
    }
  EXPECT_FLOAT_EQ(back.texels[1000].r, 1.0f);  // the hot texel clips at the range
}

TEST(MapEncodingPng8, SrgbAtAPercentileKeepsTheDarksThatLinearAtTheMaximumLoses) {
  const Lightmap m = decades();
  const Png8Error linearMax = measurePng8(m, png8Options(false, 100.0));
  const Png8Error srgbP999 = measurePng8(m, png8Options(true, 99.9));
  // Linear over [0, 50]: a code is 0.196; blue (v/4) rounds to 0 below 0.39, i.e. for the darkest
  // log(2·0.25/0.098)/log(1000) ≈ 76% of the ramp.
  EXPECT_NEAR(linearMax.zeroFraction, 0.76, 0.02);
  EXPECT_GT(linearMax.relErrorP90, 0.99);  // those channels are lost entirely
  // sRGB over [0, 2]: the smallest blue, 5e-4/2 = 2.5e-4 of the range, is 0.82 of a code: no zeros,
  // and 9 in 10 channels within 10% (the darkest tenth sits on the curve's linear toe, a few codes).
  EXPECT_EQ(srgbP999.zeroFraction, 0.0);
  EXPECT_LT(srgbP999.relErrorP90, 0.1);
  std::printf("decades: linear/max zero %.4f p90 %.4f | srgb/p99.9 zero %.4f p90 %.4f\n", linearMax.zeroFraction, linearMax.relErrorP90,
              srgbP999.zeroFraction, srgbP999.relErrorP90);
  EXPECT_NEAR(srgbP999.clippedFraction, 1.0 / 1001.0, 1e-9);  // only the hot texel
}

namespace {

// A page whose first row ramps from 0 to `peak` (red; green half of it, blue 0) and whose second row is 0.
Lightmap ramp(float peak, bool signedValues) {
  Lightmap m;
  m.page = 3;
  m.width = 256;
  m.height = 2;
  for (int i = 0; i < m.width; ++i) {
    const float t = float(i) / float(m.width - 1);
    const float v = signedValues ? peak * (2.0f * t - 1.0f) : peak * t;
    m.texels.push_back(glm::vec3(v, 0.5f * v, 0.0f));
  }
  m.texels.resize(m.size(), glm::vec3(0.0f));
  m.valid.assign(m.size(), 1);
  return m;
}

// Encodes and decodes `m` and checks every channel within the encoding's stated tolerance; returns the
// encoded page.
EncodedMap expectRoundTrip(const MapEncoding& encoding, const Lightmap& m, const MapEncodeOptions& options) {
  const EncodedMap e = encoding.encode(m, options);
  EXPECT_EQ(e.metadata.page, m.page);
  const DecodedMap d = encoding.decode(e.bytes.data(), e.bytes.size(), e.metadata, "ramp");
  EXPECT_EQ(d.map.width, m.width);
  EXPECT_EQ(d.map.height, m.height);
  if (d.map.texels.size() != m.texels.size()) {
    ADD_FAILURE() << "decoded " << d.map.texels.size() << " texels of " << m.texels.size();
    return e;
  }
  for (size_t i = 0; i < m.texels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const float v = m.texels[i][c];
      EXPECT_NEAR(d.map.texels[i][c], v, encoding.tolerance(v, e.metadata) + 1e-6) << encoding.name() << " texel " << i << " channel " << c;
    }
  return e;
}

}  // namespace

TEST(MapEncoding, RegistryNamesEachEncodingOnce) {
  EXPECT_EQ(mapEncoding(MapEncodingKind::Png8).kind(), MapEncodingKind::Png8);
  EXPECT_STREQ(mapEncoding(MapEncodingKind::Png8).name(), "png8");
  EXPECT_STREQ(mapEncoding(MapEncodingKind::Png8).mimeType(), "image/png");
  EXPECT_EQ(mapEncoding(MapEncodingKind::Exr).kind(), MapEncodingKind::Exr);
  EXPECT_STREQ(mapEncoding(MapEncodingKind::Exr).name(), "exr");
}

// MOZ_lightmap: the client decodes the PNG (sRGB curve, as extras.colorSpace says) and multiplies by the
// intensity; that product is the map value within one 8-bit sRGB step at the value × intensity.
TEST(MapEncoding, Png8SrgbRampRoundTripsAndDecodedTimesIntensityIsTheValue) {
  const float peak = 3.7f;
  const Lightmap m = ramp(peak, false);
  MapEncodeOptions o;
  o.percentile = 100.0;
  const EncodedMap e = expectRoundTrip(png8(), m, o);
  EXPECT_FLOAT_EQ(e.metadata.intensity, peak);  // the range is the page's maximum at the 100th percentile
  EXPECT_TRUE(e.metadata.srgb);
  EXPECT_FALSE(e.metadata.signedValues);
  EXPECT_EQ(e.stored.name, "lightmap_3");
  // The spec's relation, with the client's own decode rather than the encoding's.
  const Texture raw = decodeImageToTexture(e.bytes.data(), e.bytes.size(), true, "ramp");
  ASSERT_EQ(raw.texels.size(), m.texels.size());
  for (size_t i = 0; i < m.texels.size(); ++i) {
    const float v = m.texels[i].r;
    EXPECT_NEAR(raw.texels[i].r * e.metadata.intensity, v, png8().tolerance(v, e.metadata) + 1e-6) << i;
    if (v == 0.0f) {
      EXPECT_EQ(raw.texels[i].r, 0.0f) << i;  // a zero stays exactly 0
    }
  }
  EXPECT_FLOAT_EQ(raw.texels[255].r, 1.0f);  // the peak is the top code
  // The tolerance is the decoded width of one code: at the peak, 1 − srgbToLinear(254.5/255) of the range.
  EXPECT_NEAR(png8().tolerance(peak, e.metadata), (1.0 - srgbToLinear(254.5f / 255.0f)) * peak, 1e-5);
}

TEST(MapEncoding, Png8LinearSignedAndUnitRampsRoundTrip) {
  MapEncodeOptions linear;
  linear.srgb = false;
  linear.percentile = 100.0;
  const EncodedMap l = expectRoundTrip(png8(), ramp(0.8f, false), linear);
  // Linear 8-bit: one code is 1/255 of the range everywhere.
  EXPECT_NEAR(png8().tolerance(0.4f, l.metadata), 0.8 / 255.0, 1e-7);

  MapEncodeOptions l1 = linear;
  l1.range = MapRange::SignedMax;
  const EncodedMap s = expectRoundTrip(png8(), ramp(2.5f, true), l1);
  EXPECT_FLOAT_EQ(s.metadata.intensity, 2.5f);  // the largest |value|
  EXPECT_TRUE(s.metadata.signedValues);

  MapEncodeOptions unit = linear;
  unit.range = MapRange::Unit;
  const EncodedMap u = expectRoundTrip(png8(), ramp(1.0f, false), unit);
  EXPECT_FLOAT_EQ(u.metadata.intensity, 1.0f);
  // The fourth channel, under colour 0: the PNG path (OpenImageIO) stores colour unassociated from alpha and
  // decodes it associated, so only a colour at or below its alpha comes back as written.
  Lightmap alpha = ramp(1.0f, false), black = ramp(0.0f, false);
  unit.alpha = &alpha;
  const EncodedMap a = expectRoundTrip(png8(), black, unit);
  const DecodedMap d = png8().decode(a.bytes.data(), a.bytes.size(), a.metadata, "unit");
  ASSERT_EQ(d.alpha.size(), alpha.texels.size());
  for (size_t i = 0; i < d.alpha.size(); ++i) EXPECT_NEAR(d.alpha[i], alpha.texels[i].x, 0.5 / 255.0 + 1e-6) << i;
}

// EXR stores float32 as written: every value, zeros and alpha included, comes back bit for bit.
TEST(MapEncoding, ExrRampRoundTripsExactly) {
  // encode() keeps its scratch file in $TMPDIR: the build folder, where the tests write.
  ASSERT_EQ(setenv("TMPDIR", std::filesystem::current_path().c_str(), 1), 0);
  const MapEncoding& exr = mapEncoding(MapEncodingKind::Exr);
  const Lightmap m = ramp(123.456f, false);
  const EncodedMap e = expectRoundTrip(exr, m, {});
  EXPECT_EQ(exr.tolerance(1.0f, e.metadata), 0.0);
  EXPECT_FLOAT_EQ(e.metadata.intensity, 1.0f);
  const DecodedMap bytes = exr.decode(e.bytes.data(), e.bytes.size(), e.metadata, "ramp");
  EXPECT_TRUE(bytes.alpha.empty());
  for (size_t i = 0; i < m.texels.size(); ++i) EXPECT_EQ(bytes.map.texels[i], m.texels[i]) << i;

  MapEncodeOptions withAlpha;
  Lightmap alpha = ramp(0.25f, false);
  withAlpha.alpha = &alpha;
  const std::filesystem::path file = "map_encoding_exr_ramp.exr";
  exr.writeFile(m, withAlpha, file, file);
  const DecodedMap back = exr.readFile(file, {});
  std::filesystem::remove(file);
  EXPECT_EQ(back.map.page, m.page);  // the page travels in the file
  ASSERT_EQ(back.alpha.size(), m.size());
  for (size_t i = 0; i < m.texels.size(); ++i) {
    EXPECT_EQ(back.map.texels[i], m.texels[i]) << i;
    EXPECT_EQ(back.alpha[i], alpha.texels[i].x) << i;
  }
}

// A client that unpacked the image itself (the scene loader) gets the same values as decode().
TEST(MapEncoding, FromStoredIsDecodeAfterTheUnpacking) {
  MapEncodeOptions l1;
  l1.srgb = false;
  l1.range = MapRange::SignedMax;
  const EncodedMap e = png8().encode(ramp(2.5f, true), l1);
  const Texture unpacked = decodeImageToTexture(e.bytes.data(), e.bytes.size(), false, "l1");
  const DecodedMap viaBytes = png8().decode(e.bytes.data(), e.bytes.size(), e.metadata, "l1");
  const DecodedMap viaStored = png8().fromStored(unpacked, e.metadata);
  ASSERT_EQ(viaStored.map.texels.size(), viaBytes.map.texels.size());
  for (size_t i = 0; i < viaBytes.map.texels.size(); ++i) EXPECT_EQ(viaStored.map.texels[i], viaBytes.map.texels[i]) << i;
  // 0 codes as 128/255: (2 · 128/255 − 1) · 2.5 = 2.5/255.
  EXPECT_NEAR(viaStored.map.texels[256].r, 2.5f / 255.0f, 1e-6f);

  Texture floats;
  floats.width = 2;
  floats.height = 1;
  floats.texels = {glm::vec4(-1.5f, 0.0f, 7.25f, 0.5f), glm::vec4(1e-8f, 3.0f, 0.0f, 1.0f)};
  const DecodedMap f = mapEncoding(MapEncodingKind::Exr).fromStored(floats, {});
  ASSERT_EQ(f.map.texels.size(), 2u);
  EXPECT_EQ(f.map.texels[0], glm::vec3(-1.5f, 0.0f, 7.25f));
  EXPECT_EQ(f.map.texels[1], glm::vec3(1e-8f, 3.0f, 0.0f));
  EXPECT_EQ(f.alpha, (std::vector<float>{0.5f, 1.0f}));
}

// The file path every encoding shares: writeFile writes encode()'s bytes, readFile decodes them back.
TEST(MapEncoding, Png8FileIsTheEncodedBytes) {
  const Lightmap m = ramp(3.7f, false);
  MapEncodeOptions o;
  o.percentile = 100.0;
  const EncodedMap e = png8().encode(m, o);
  const std::filesystem::path file = "map_encoding_png8_ramp.png";
  png8().writeFile(m, o, file, file);
  std::ifstream in(file, std::ios::binary);
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  EXPECT_EQ(bytes, e.bytes);
  const DecodedMap back = png8().readFile(file, e.metadata);
  std::filesystem::remove(file);
  const DecodedMap direct = png8().decode(e.bytes.data(), e.bytes.size(), e.metadata, "ramp");
  ASSERT_EQ(back.map.texels.size(), direct.map.texels.size());
  for (size_t i = 0; i < direct.map.texels.size(); ++i) EXPECT_EQ(back.map.texels[i], direct.map.texels[i]) << i;
  EXPECT_THROW(png8().readFile("map_encoding_no_such_file.png", e.metadata), Error);
}
