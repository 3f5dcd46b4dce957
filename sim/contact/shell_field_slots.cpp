// The shells' fields inside the implicit grid step (field_slots.h).
#include <cstring>
#include <unordered_map>

#include "sim/contact/shell_fields.h"

namespace shellmpm {

void ShellFields::slots(const SparseGrid& combined, const std::vector<GridShell>& shells,
                        const SkipFn& skip, const ColliderGate* gate, FieldSlots& out,
                        bool serial) {
  const std::size_t K = fields_.size(), ng = combined.num_grid_blocks();
  out = FieldSlots{};
  out.slot_of.assign(K, {});
  out.control.resize(K);
  slot_r_.clear();
  slot_bits_.assign(ng, 0);
  one_bits_.assign(ng, 0);
  slotted_ = true;
  if (!implicit_) return;
  // The relative velocities at nodes with more bodies than a group code holds stay the
  // rule's for before_g2p, but are no offset the solve sees: set aside while the control
  // points' offsets are summed. Nodes under a collider gate keep one velocity, the solve's
  // (with the collider's constraint): the gate's per-body condition after the solve moved
  // the bodies there by velocities the solve never saw.
  std::vector<std::pair<Vec3*, Vec3>> aside;
  std::vector<Body> bodies;
  // In the grid's order (the slots' order is the same for any thread count).
  for (std::size_t g = 0; g < ng; ++g) {
    if (!shared_[g]) continue;
    const Vec3i corner = unpack_block(combined.gblock_key[g]) * kBlockSize;
    for (int n = 0; n < kBlockNodes; ++n) {
      if (!(shared_[g] >> n & 1)) continue;
      const Vec3i node = corner + Vec3i(n >> 4, (n >> 2) & 3, n & 3);
      const GridNode& cn = combined.gblock_nodes[g][n];
      const Real ms = node_bodies(g, n, bodies);
      const std::size_t cnt = bodies.size();
      if (skip && skip(node)) {
        // One velocity (before_g2p would drop the relative velocities the same way).
        for (Body& B : bodies) *B.r = Vec3::Zero();
        r_bulk_[g][n] = Vec3::Zero();
        continue;
      }
      if (gate && gate->engaged(g, n)) {
        for (Body& B : bodies) *B.r = Vec3::Zero();
        r_bulk_[g][n] = Vec3::Zero();
        one_bits_[g] |= std::uint64_t(1) << n;
        continue;
      }
      const bool fits = cnt + 1 <= std::size_t(kMaxGroupBodies);
      if (!fits) {
        for (Body& B : bodies) {
          aside.emplace_back(B.r, *B.r);
          *B.r = Vec3::Zero();
        }
        continue;
      }
      const Real mk = cn.m - ms;
      const bool bulk = mk >= kBulkMin * cn.m;
      const Vec3 p(cn.v[0], cn.v[1], cn.v[2]);
      const Vec3 v0 = p / cn.m;
      const Union uf = node_groups(group_[g][n], bodies, bulk);
      const int base = uf.find(int(cnt));
      // Each group moves with the velocity of its reference body (the bulk field for the
      // base group where there is one, else its first body); the others keep their offset
      // from it, the rule's outcome.
      Vec3 post[kMaxGroupBodies], pre_p[kMaxGroupBodies];
      Real m[kMaxGroupBodies];
      Vec3 ps = Vec3::Zero();
      const std::size_t nb = cnt;
      for (std::size_t i = 0; i < nb; ++i) {
        const Node& f = *bodies[i].f;
        m[i] = f.m;
        pre_p[i] = f.m * Vec3(f.p[0], f.p[1], f.p[2]);
        post[i] = v0 + *bodies[i].r;
        ps += pre_p[i];
      }
      m[nb] = std::max(mk, Real(0));
      pre_p[nb] = p - ps;
      post[nb] = bulk ? Vec3(v0 + r_bulk_[g][n]) : v0;
      const auto ref = [&](int root) { return root == base && bulk ? int(nb) : root; };
      Real M[kMaxGroupBodies] = {};
      Vec3 P[kMaxGroupBodies];
      Vec3 off[kMaxGroupBodies];
      for (std::size_t i = 0; i <= nb; ++i) P[i] = Vec3::Zero();
      for (std::size_t i = 0; i <= nb; ++i) {
        const int root = uf.find(int(i));
        off[i] = i == nb && !bulk ? Vec3::Zero() : Vec3(post[i] - post[ref(root)]);
        M[root] += m[i];
        P[root] += pre_p[i] - m[i] * off[i];
      }
      // The base group replaces the node's mass and velocity; the others get slots.
      const auto gi = static_cast<std::uint32_t>(g * kBlockNodes + std::size_t(n));
      int slot_of_root[kMaxGroupBodies];
      for (int& k : slot_of_root) k = -1;
      for (std::size_t i = 0; i <= nb; ++i) {
        const int root = uf.find(int(i));
        if (root != int(i)) continue;
        if (root == base) {
          out.base_node.push_back(gi);
          out.base_m.push_back(M[root]);
          out.base_v.push_back(M[root] > 0 ? Vec3(P[root] / M[root]) : v0);
          continue;
        }
        slot_of_root[root] = int(out.slot_node.size());
        out.slot_node.push_back(gi);
        out.slot_m.push_back(M[root]);
        out.slot_v.push_back(P[root] / M[root]);
        out.slot_start.push_back(post[root]);
      }
      for (std::size_t i = 0; i < nb; ++i) {
        *bodies[i].r = off[i];
        const int k = slot_of_root[uf.find(int(i))];
        if (k < 0) continue;
        std::vector<int>& so = out.slot_of[std::size_t(bodies[i].shell)];
        if (so.empty()) so.assign(ng * kBlockNodes, -1);
        so[gi] = k;
        slot_r_.emplace_back(bodies[i].r, k);
      }
      r_bulk_[g][n] = Vec3::Zero();
      slot_bits_[g] |= std::uint64_t(1) << n;
    }
  }
  for (std::size_t s = 0; s < K; ++s) {
    out.control[s].assign(shells[s].shell->size(), Vec3::Zero());
    each_relative(fields_[s], serial,
                  [&](std::uint32_t j, const Vec3& dv, const Mat3&) { out.control[s][j] = dv; });
  }
  for (const auto& [r, v] : aside) *r = v;
}

ShellFields::Union ShellFields::node_groups(std::uint64_t code, const std::vector<Body>& bodies,
                                            bool bulk) {
  // The rule's groups, with a shell's fold classes in one (its control points read one
  // unknown at a node) and the bulk field (or its sliver at a node of shells) in the base
  // group: the node's u.
  const std::size_t cnt = bodies.size();
  Union uf(int(cnt) + 1);
  for (std::size_t i = 0; i <= cnt; ++i) uf.join(int(i), int(code >> (4 * i) & 15));
  for (std::size_t i = 0; i < cnt; ++i)
    for (std::size_t j = i + 1; j < cnt; ++j)
      if (bodies[i].shell == bodies[j].shell) uf.join(int(i), int(j));
  if (!bulk) uf.join(int(cnt), 0);
  return uf;
}

bool ShellFields::regroup(const SparseGrid& combined,
                          const std::vector<std::array<GridNode, kBlockNodes>>& before,
                          const std::vector<Vec3>& slot_vel) {
  std::unordered_map<const Vec3*, int> slot_of_r;
  for (const auto& [r, k] : slot_r_) slot_of_r[r] = k;
  struct Update {
    std::size_t g;
    int n;
    std::uint64_t code;
    std::vector<std::pair<Vec3*, Vec3>> r;  ///< each body's new relative velocity
    Vec3 rk;
  };
  std::vector<Update> updates;
  bool changed = false;
  std::vector<Body> bodies;
  for (std::size_t g = 0; g < combined.num_grid_blocks(); ++g) {
    if (g >= slot_bits_.size() || !slot_bits_[g]) continue;
    for (int n = 0; n < kBlockNodes; ++n) {
      if (!(slot_bits_[g] >> n & 1)) continue;
      const GridNode& b0 = before[g][n];
      const GridNode& nd = combined.gblock_nodes[g][n];
      const Vec3 v0 = Vec3(b0.v[0], b0.v[1], b0.v[2]) / b0.m;
      const Vec3 u(nd.v[0], nd.v[1], nd.v[2]);
      const Real ms = node_bodies(g, n, bodies);
      const std::size_t cnt = bodies.size();
      const Real mk = b0.m - ms;
      const bool bulk = mk >= kBulkMin * b0.m;
      const Union old = node_groups(group_[g][n], bodies, bulk);
      // Each body's solved velocity: its group's unknown plus its offset.
      for (Body& B : bodies) {
        const auto it = slot_of_r.find(B.r);
        B.vel = (it == slot_of_r.end() ? u : slot_vel[std::size_t(it->second)]) + *B.r;
        body_geometry(B);
      }
      Vec3 vk = u;
      Union now = old;
      shell_pairs(bodies, &now);
      if (bulk) bulk_pairs(bodies, g < bulk_mom_.size() ? &bulk_mom_[g][n] : nullptr, mk, vk, &now);
      bool joined = false;
      for (std::size_t i = 0; i <= cnt && !joined; ++i)
        for (std::size_t j = i + 1; j <= cnt && !joined; ++j)
          joined = old.find(int(i)) != old.find(int(j)) && now.find(int(i)) == now.find(int(j));
      changed |= joined;
      Update up{g, n, 0, {}, bulk ? Vec3(vk - v0) : Vec3::Zero()};
      for (std::size_t i = 0; i <= cnt; ++i) up.code |= std::uint64_t(now.find(int(i))) << (4 * i);
      for (const Body& B : bodies) up.r.emplace_back(B.r, B.vel - v0);
      updates.push_back(std::move(up));
    }
  }
  if (!changed) return false;
  // The solved (and ruled) velocities become the rule's outcome slots() reads.
  for (const Update& up : updates) {
    group_[up.g][up.n] = up.code;
    for (const auto& [r, v] : up.r) *r = v;
    r_bulk_[up.g][up.n] = up.rk;
  }
  return true;
}

void ShellFields::take_solution(const SparseGrid& combined, const FieldSlots& fs,
                                const std::vector<Vec3>& slot_vel) {
  for (const auto& [r, k] : slot_r_) {
    const std::uint32_t gi = fs.slot_node[std::size_t(k)];
    const GridNode& nd = combined.gblock_nodes[gi / kBlockNodes][gi % kBlockNodes];
    *r += slot_vel[std::size_t(k)] - Vec3(nd.v[0], nd.v[1], nd.v[2]);
  }
}

}  // namespace shellmpm
