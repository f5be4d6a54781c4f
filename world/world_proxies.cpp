// The shapes' broadphase proxies: made when a shape is registered, and
// refitted where their bodies have moved, at a step's start (after changes
// made through the API) and at its end (so queries between steps see the
// shapes where they are).
//
// A refit is a shape's world box and a test against its fat box; few
// proxies leave their fat boxes in a step (460 to 880 of the 5,050-box
// pyramid's), and only those change the tree. With many shapes and a
// worker pool the boxes and tests run on the pool's threads, and the
// changes go to the broadphase afterwards on the calling thread, in slot
// order: the order one thread would make them in, so the tree is the same.
#include "collision/aabb.hpp"
#include "world/parallel_thresholds.hpp"
#include "world/step_stages.hpp"

namespace cairn::detail {

void WorldImpl::registerShape(BodyId id, std::int32_t index_in_body) {
  Body& b = body(id);
  std::int32_t slot;
  if (!free_shapes_.empty()) {
    slot = free_shapes_.back();
    free_shapes_.pop_back();
  } else {
    slot = static_cast<std::int32_t>(shapes_.size());
    shapes_.emplace_back();
    shapes_.back().alive = false;
  }
  ShapeRef& ref = shapes_[static_cast<size_t>(slot)];
  ref.body = id;
  ref.index = index_in_body;
  ref.alive = true;
  const ShapeDesc& shape = b.shapes[static_cast<size_t>(index_in_body)];
  Aabb box = bodyShapeAabb(shape, b.transform());
  if (!box.isInfinite()) box = box.expanded(settings_.contact_margin);
  ref.proxy = broadphase_.createProxy(box, slot, Vec3::Zero(), id.index);  // a body's own shapes never pair
  proxy_fits_.resize(shapes_.size());  // the slot's box is fitted afresh
  proxy_fits_[static_cast<size_t>(slot)] = {};
  broadphase_.setFilter(ref.proxy, b.collision_group, b.collision_mask);
  b.shape_ids[static_cast<size_t>(index_in_body)] = slot;
}

bool WorldImpl::fitProxy(std::size_t slot, Real h, Aabb& box) {
  const ShapeRef& ref = shapes_[slot];
  const Body& b = body(ref.body);
  ProxyFit& fit = proxy_fits_[slot];
  const Real margin = settings_.contact_margin;
  if (fit.h == h && fit.margin == margin && fit.ccd == b.ccd && fit.x == b.position && fit.v == b.linear_velocity &&
      fit.q.coeffs() == b.orientation.coeffs())
    return false;
  fit = {b.position, b.linear_velocity, b.orientation, h, margin, b.ccd};
  const ShapeDesc& shape = b.shapes[static_cast<size_t>(ref.index)];
  box = bodyShapeAabb(shape, b.transform());
  if (!box.isInfinite()) box = box.expanded(contactReach(b, margin, h));  // as registerShape does
  return true;
}

void WorldImpl::refitProxy(std::size_t slot, Real h) {
  Aabb box;
  if (fitProxy(slot, h, box))
    broadphase_.moveProxy(shapes_[slot].proxy, box, body(shapes_[slot].body).linear_velocity * h);
}

void WorldImpl::forgetProxyFits() { proxy_fits_.assign(shapes_.size(), ProxyFit{}); }

namespace {

// Refits the proxies of the slots for which `take(slot)` holds: on the
// pool's threads when there are many, each keeping the slots whose proxies
// change (a slot's fit is its own), then those changes in slot order.
// "Many" counts the shapes less one per body asleep at the last islands
// stage (an asleep body's shapes are a test and a skip; most bodies have
// one shape): only the split depends on it.
template <class Take>
void refitProxies(WorldImpl& w, StepContext& ctx, Real h, Take&& take) {
  const int count = static_cast<int>(w.shapes_.size());
  if (!w.pool_ || count - ctx.asleep_bodies < kParallelProxies) {
    for (size_t slot = 0; slot < w.shapes_.size(); ++slot)
      if (take(slot)) w.refitProxy(slot, h);
    return;
  }
  ctx.proxy_moves.resize(static_cast<size_t>(w.pool_->threads()));
  for (std::vector<StepContext::ProxyMove>& moves : ctx.proxy_moves) moves.clear();  // a thread given no range adds none
  w.pool_->parallelFor(count, [&](int begin, int end) {
    std::vector<StepContext::ProxyMove>& moves = ctx.proxy_moves[static_cast<size_t>(WorkerPool::currentThread())];
    for (int k = begin; k < end; ++k) {
      const auto slot = static_cast<size_t>(k);
      Aabb box;
      if (!take(slot) || !w.fitProxy(slot, h, box)) continue;
      const ShapeRef& ref = w.shapes_[slot];
      if (w.broadphase_.moveChanges(ref.proxy, box, w.body(ref.body).linear_velocity * h)) moves.push_back({k, box});
    }
  });
  for (const std::vector<StepContext::ProxyMove>& moves : ctx.proxy_moves)  // the threads' ranges, in order
    for (const StepContext::ProxyMove& m : moves) {
      const ShapeRef& ref = w.shapes_[static_cast<size_t>(m.slot)];
      w.broadphase_.moveProxy(ref.proxy, m.box, w.body(ref.body).linear_velocity * h);
    }
}

}  // namespace

void WorldImpl::moveProxies(BodyId only, Real h) {
  if (!only.isWorld()) {
    for (size_t slot = 0; slot < shapes_.size(); ++slot)
      if (shapes_[slot].alive && shapes_[slot].body.index == only.index) refitProxy(slot, h);
    return;
  }
  refitProxies(*this, ctx_, h, [&](size_t slot) {
    const ShapeRef& ref = shapes_[slot];
    if (!ref.alive) return false;
    const Body& b = body(ref.body);
    return b.type != BodyType::Static && !b.asleep;
  });
}

void WorldImpl::moveAwakeProxies(Real h) {
  refitProxies(*this, ctx_, h, [&](size_t slot) {
    const ShapeRef& ref = shapes_[slot];
    if (!ref.alive || !ctx_.moves(static_cast<size_t>(ref.body.index))) return false;  // static or asleep: still there
    const Body& b = body(ref.body);
    return b.type != BodyType::Static && !b.asleep;
  });
}

}  // namespace cairn::detail
