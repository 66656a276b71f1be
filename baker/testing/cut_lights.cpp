#include "testing/cut_lights.h"

namespace irbake::testing {

namespace {
VplEvalOptions directOnly() {
  VplEvalOptions eval;
  eval.includeVpls = false;
  return eval;
}
}  // namespace

BakeInputs CutLightsCase::bruteInputs() const { return BakeInputs{whole, *wholeRt, pages, vpls, directOnly(), {}}; }

BakeInputs CutLightsCase::culledInputs() const {
  BakeInputs in{culled, *culledRt, pages, vpls, directOnly(), {}};
  in.lightGrid = grid.get();
  return in;
}

std::unique_ptr<CutLightsCase> cutLightsCase(Scene whole, float fraction, TexelSamples page) {
  auto c = std::make_unique<CutLightsCase>();
  c->whole = std::move(whole);
  c->culled = c->whole;
  LightCullOptions o;
  o.fraction = fraction;
  c->reach = settleLightReach(c->culled, c->culled.bounds(), o);
  applyLightCutoffs(c->culled, c->reach);
  c->grid = std::make_unique<LightGrid>(c->culled, c->reach, c->culled.bounds());
  c->pages.push_back(std::move(page));
  c->wholeRt = std::make_unique<RayTracer>(c->whole);
  c->culledRt = std::make_unique<RayTracer>(c->culled);
  return c;
}

}  // namespace irbake::testing
