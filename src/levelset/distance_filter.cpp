// SPDX-License-Identifier: Apache-2.0
#include "levelset/distance_filter.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "vdb/parallel.h"

namespace sweepers {

namespace {

int floorDiv(int a, int m) {
    return a >= 0 ? a / m : -((-a + m - 1) / m);
}
openvdb::Coord floorDiv(const openvdb::Coord& a, int m) {
    return {floorDiv(a.x(), m), floorDiv(a.y(), m), floorDiv(a.z(), m)};
}
// The first node of the block holding node k.
openvdb::Coord blockOrigin(const openvdb::Coord& k) {
    return k & ~7;
}
openvdb::Coord times(const openvdb::Coord& k, int m) {
    return {k.x() * m, k.y() * m, k.z() * m};
}
std::size_t offset(int x, int y, int z) {
    return std::size_t(x) * 64 + std::size_t(y) * 8 + std::size_t(z);
}

} // namespace

DistanceFilter::DistanceFilter(const Grid& grid, double sigma, const openvdb::Coord& center)
    : grid_(grid), center_(center) {
    sigma = std::max(sigma, kSmallestSigma);
    // The widest lattice whose own Gaussian keeps a standard deviation of 0.7 node or more
    // once the splat and the slice have taken their share: s^2 - (m^2 - 1) / 3 >= 0.49 m^2.
    // (Sampled at 0.7 node, a Gaussian's decay differs from the continuous one's by 1e-4 for
    // long waves, 1% where it has fallen to a half.) From kSmallestSigma on, m >= 2.
    m_ = std::max(1, int(std::floor(std::sqrt((sigma * sigma + 1.0 / 3.0) / (0.49 + 1.0 / 3.0)))));
    const double rest = sigma * sigma - (double(m_) * m_ - 1.0) / 3.0;
    stats_.spacing = m_;
    stats_.latticeSigma = std::sqrt(rest) / m_;
    // 3.5 standard deviations (the weight left out is about 5e-4 of the whole); a block's
    // neighbours hold it (the lattice's sigma stays below 1.3 nodes for m >= 2: 5 nodes).
    stats_.radius = std::min(8, int(std::ceil(3.5 * stats_.latticeSigma)));
    kernel_.resize(std::size_t(stats_.radius) * 2 + 1);
    double sum = 0.0;
    for (int d = -stats_.radius; d <= stats_.radius; ++d) {
        const double w = std::exp(-0.5 * d * d / (stats_.latticeSigma * stats_.latticeSigma));
        const int at = d + stats_.radius;
        kernel_[std::size_t(at)] = float(w);
        sum += w;
    }
    for (float& w : kernel_)
        w = float(w / sum);
}

int DistanceFilter::blockOf(const openvdb::Coord& o) const {
    const auto it = index_.find(o);
    return it == index_.end() ? -1 : it->second;
}

int DistanceFilter::insertBlock(const openvdb::Coord& o) {
    const auto [it, made] = index_.emplace(o, int(origin_.size()));
    if (made) origin_.push_back(o);
    return it->second;
}

void DistanceFilter::plan(const std::vector<const Leaf*>& leaves, const VoxelList& wanted) {
    leaves_ = leaves;
    // Backwards from the nodes the voxels asked for read (the blocks of `wanted`'s leaves'
    // nodes): the z pass gives them, reading the y pass's output a block either side along z,
    // which reads the x pass's a block either side along y, which reads the splat's a block
    // either side along x (the blur reaches at most 8 nodes).
    const auto leafBlocks = [&](const openvdb::Coord& o, auto&& each) {
        const openvdb::Coord lo = blockOrigin(floorDiv(o, m_)),
                             hi = blockOrigin(floorDiv(o.offsetBy(6 + m_), m_));
        for (int x = lo.x(); x <= hi.x(); x += 8)
            for (int y = lo.y(); y <= hi.y(); y += 8)
                for (int z = lo.z(); z <= hi.z(); z += 8)
                    each(openvdb::Coord(x, y, z));
    };
    for (const LeafVoxels& lv : wanted)
        leafBlocks(lv.origin, [&](const openvdb::Coord& b) { insertBlock(b); });
    for (int axis = 2; axis >= 0; --axis) {
        const std::size_t end = origin_.size();
        pass_[std::size_t(axis)].clear();
        for (std::size_t b = 0; b < end; ++b)
            pass_[std::size_t(axis)].push_back(int(b));
        for (std::size_t b = 0; b < end; ++b)
            for (const int side : {-8, 8}) {
                openvdb::Coord n = origin_[b];
                n[axis] += side;
                insertBlock(n);
            }
    }
    // The leaves each block gathers from: those whose voxels' nodes lie in it.
    splatFrom_.assign(origin_.size(), {});
    for (std::size_t l = 0; l < leaves_.size(); ++l)
        leafBlocks(leaves_[l]->origin(), [&](const openvdb::Coord& o) {
            const int b = blockOf(o);
            if (b >= 0) splatFrom_[std::size_t(b)].push_back(int(l));
        });
    neighbour_.resize(origin_.size());
    for (std::size_t b = 0; b < origin_.size(); ++b)
        for (int axis = 0; axis < 3; ++axis)
            for (int side = 0; side < 2; ++side) {
                openvdb::Coord n = origin_[b];
                n[axis] += side ? 8 : -8;
                neighbour_[b][std::size_t(axis) * 2 + std::size_t(side)] = blockOf(n);
            }
    stats_.inputLeaves = 0;
    for (const auto& from : splatFrom_)
        stats_.inputLeaves += from.size();
    stats_.blocks = origin_.size();
    stats_.outputBlocks = pass_[2].size();
    // The splat: 8 nodes of 5 fields a voxel; the blur: a pass of 5 fields along each axis.
    const double taps = double(kernel_.size());
    stats_.work =
        double(stats_.inputLeaves) * 512.0 * 8.0 * kFields +
        double(pass_[0].size() + pass_[1].size() + pass_[2].size()) * 512.0 * kFields * taps;
}

void DistanceFilter::splat() {
    // Zeroed below where the splat sums; each pass writes every node of the blocks it makes.
    a_.resize(origin_.size());
    b_.resize(origin_.size());
    const float bg = grid_.background();
    const float toVoxels = float(1.0 / grid_.voxelSize()[0]);
    const int m = m_;
    const float inv = 1.0f / float(m);
    parallelFor(tbb::blocked_range<std::size_t>(0, origin_.size()), [&](const auto& range) {
        // A leaf's sums along z (by row and z node), then along y (by x, y node and z node).
        std::vector<float> alongZ, alongY;
        for (std::size_t b = range.begin(); b != range.end(); ++b) {
            Block& out = a_[b];
            out.f.fill(0.0f);
            const openvdb::Coord first = origin_[b];
            for (const int l : splatFrom_[b]) {
                const Leaf& leaf = *leaves_[std::size_t(l)];
                const openvdb::Coord o = leaf.origin(), lo = floorDiv(o, m);
                // Along each axis, for each of the leaf's 8 coordinates: its node (at or below
                // it, from the leaf's first node) and the weights of that node and the next.
                struct Axis {
                    std::array<int, 8> node;
                    std::array<float, 8> w0, w1;
                    int nodes = 0;
                };
                std::array<Axis, 3> axes;
                for (int a = 0; a < 3; ++a) {
                    Axis& ax = axes[std::size_t(a)];
                    for (int c = 0; c < 8; ++c) {
                        const int x = o[a] + c, k0 = floorDiv(x, m), r = x - k0 * m;
                        ax.node[std::size_t(c)] = k0 - lo[a];
                        ax.w0[std::size_t(c)] = float(m - r) * inv;
                        ax.w1[std::size_t(c)] = float(r) * inv;
                    }
                    ax.nodes = floorDiv(o[a] + 6 + m, m) - lo[a] + 1;
                }
                const Axis &X = axes[0], &Y = axes[1], &Z = axes[2];
                const std::size_t nz = std::size_t(Z.nodes), ny = std::size_t(Y.nodes);
                // The separable tent, one axis at a time: each voxel's 5 values into its two
                // z nodes, each row's z nodes into two y nodes, each slice into two x nodes.
                alongZ.assign(64 * nz * kFields, 0.0f);
                const float* v = leaf.buffer().data();
                const auto& mask = leaf.valueMask();
                std::array<bool, 64> row{};
                for (int x = 0; x < 8; ++x)
                    for (int y = 0; y < 8; ++y) {
                        const std::size_t r = std::size_t(x) * 8 + std::size_t(y);
                        float* g = alongZ.data() + r * nz * kFields;
                        const openvdb::Coord rel = o.offsetBy(x, y, 0) - center_;
                        for (int z = 0; z < 8; ++z) {
                            const openvdb::Index i = openvdb::Index(r * 8 + std::size_t(z));
                            if (!mask.isOn(i) || !(std::abs(v[i]) < bg)) continue;
                            row[r] = true;
                            const float values[kFields] = {1.0f, v[i] * toVoxels, float(rel.x()),
                                                           float(rel.y()), float(rel.z() + z)};
                            const std::size_t k = std::size_t(Z.node[std::size_t(z)]);
                            // (The next node only where the voxel lies past this one: a
                            // voxel on a node's plane may be at the leaf's last node.)
                            const float w0 = Z.w0[std::size_t(z)], w1 = Z.w1[std::size_t(z)];
                            for (int f = 0; f < kFields; ++f)
                                g[k * kFields + std::size_t(f)] += w0 * values[f];
                            if (w1 > 0.0f)
                                for (int f = 0; f < kFields; ++f)
                                    g[(k + 1) * kFields + std::size_t(f)] += w1 * values[f];
                        }
                    }
                alongY.assign(8 * ny * nz * kFields, 0.0f);
                std::array<bool, 8> slice{};
                for (int x = 0; x < 8; ++x)
                    for (int y = 0; y < 8; ++y) {
                        const std::size_t r = std::size_t(x) * 8 + std::size_t(y);
                        if (!row[r]) continue;
                        slice[std::size_t(x)] = true;
                        const float* g = alongZ.data() + r * nz * kFields;
                        const std::size_t k = std::size_t(Y.node[std::size_t(y)]);
                        float* h0 = alongY.data() + (std::size_t(x) * ny + k) * nz * kFields;
                        const float w0 = Y.w0[std::size_t(y)], w1 = Y.w1[std::size_t(y)];
                        for (std::size_t j = 0; j < nz * kFields; ++j)
                            h0[j] += w0 * g[j];
                        if (w1 > 0.0f) {
                            float* h1 = h0 + nz * kFields;
                            for (std::size_t j = 0; j < nz * kFields; ++j)
                                h1[j] += w1 * g[j];
                        }
                    }
                for (int x = 0; x < 8; ++x) {
                    if (!slice[std::size_t(x)]) continue;
                    for (int dx = 0; dx < 2; ++dx) {
                        const int nx = lo.x() + X.node[std::size_t(x)] + dx - first.x();
                        const float wx = dx ? X.w1[std::size_t(x)] : X.w0[std::size_t(x)];
                        if (nx < 0 || nx > 7 || wx == 0.0f) continue;
                        for (std::size_t ky = 0; ky < ny; ++ky) {
                            const int yy = lo.y() + int(ky) - first.y();
                            if (yy < 0 || yy > 7) continue;
                            const float* h =
                                alongY.data() + (std::size_t(x) * ny + ky) * nz * kFields;
                            for (std::size_t kz = 0; kz < nz; ++kz) {
                                const int zz = lo.z() + int(kz) - first.z();
                                if (zz < 0 || zz > 7) continue;
                                const std::size_t at = offset(nx, yy, zz);
                                for (int f = 0; f < kFields; ++f)
                                    out.f[std::size_t(f) * 512 + at] +=
                                        wx * h[kz * kFields + std::size_t(f)];
                            }
                        }
                    }
                }
            }
        }
    });
}

// One pass of the separable Gaussian along an axis, over the given blocks: each line of a
// block is read with the lines of its two neighbours along the axis (zero where none).
void DistanceFilter::pass(int axis, const std::vector<int>& blocks, const std::vector<Block>& from,
                          std::vector<Block>& to) const {
    const int radius = stats_.radius;
    const float* kernel = kernel_.data() + radius;
    // A block as [outer][8 places along the axis][inner]: the `inner` values at one place are
    // contiguous (64 along x, 8 along y, 1 along z), so each output row is a weighted sum of
    // whole rows, which the compiler vectorizes.
    const int inner = axis == 0 ? 64 : axis == 1 ? 8 : 1, outer = 64 / inner;
    parallelFor(tbb::blocked_range<std::size_t>(0, blocks.size()), [&](const auto& range) {
        for (std::size_t k = range.begin(); k != range.end(); ++k) {
            const std::size_t b = std::size_t(blocks[k]);
            const int before = neighbour_[b][std::size_t(axis) * 2],
                      after = neighbour_[b][std::size_t(axis) * 2 + 1];
            const Block* parts[3] = {before >= 0 ? &from[std::size_t(before)] : nullptr, &from[b],
                                     after >= 0 ? &from[std::size_t(after)] : nullptr};
            Block& out = to[b];
            if (inner == 1) {
                // Along z each row is 8 contiguous values: the row and its neighbours' side by
                // side, and the 8 outputs summed tap by tap.
                for (std::size_t row = 0; row < std::size_t(kFields) * 64; ++row) {
                    std::array<float, 24> line{};
                    for (int part = 0; part < 3; ++part)
                        if (parts[part])
                            std::copy_n(parts[part]->f.data() + row * 8, 8,
                                        line.data() + std::size_t(part) * 8);
                    std::array<float, 8> sum{};
                    for (int d = -radius; d <= radius; ++d)
                        for (int p = 0; p < 8; ++p) {
                            const int q = 8 + p + d; // in the row and its neighbours
                            sum[std::size_t(p)] += kernel[d] * line[std::size_t(q)];
                        }
                    std::copy(sum.begin(), sum.end(), out.f.data() + row * 8);
                }
                continue;
            }
            for (int f = 0; f < kFields; ++f)
                for (int o = 0; o < outer; ++o) {
                    const std::size_t first =
                        std::size_t(f) * 512 + std::size_t(o) * 8 * std::size_t(inner);
                    for (int p = 0; p < 8; ++p) {
                        float* row = out.f.data() + first + std::size_t(p * inner);
                        std::fill(row, row + inner, 0.0f);
                        for (int d = -radius; d <= radius; ++d) {
                            const int q = p + d + 8; // 0 to 23: the place in the three blocks
                            const Block* part = parts[q >> 3];
                            if (!part) continue;
                            const float* in = part->f.data() + first + std::size_t((q & 7) * inner);
                            const float w = kernel[d];
                            for (int i = 0; i < inner; ++i)
                                row[i] += w * in[i];
                        }
                    }
                }
        }
    });
}

void DistanceFilter::blur() {
    pass(0, pass_[0], a_, b_);
    pass(1, pass_[1], b_, a_);
    pass(2, pass_[2], a_, b_);
    // The averages: the weighted sums over the weight, where the band has any weight.
    parallelFor(tbb::blocked_range<std::size_t>(0, pass_[2].size()), [&](const auto& range) {
        for (std::size_t k = range.begin(); k != range.end(); ++k) {
            Block& block = b_[std::size_t(pass_[2][k])];
            for (std::size_t n = 0; n < 512; ++n) {
                const float w = block.f[n];
                if (w > 1e-6f) {
                    for (std::size_t f = 1; f < kFields; ++f)
                        block.f[f * 512 + n] /= w;
                } else {
                    block.f[n] = 0.0f;
                }
            }
        }
    });
}

void DistanceFilter::read(const openvdb::Coord& origin, const leafwords::Words& which,
                          const std::array<openvdb::Vec3f, 512>& gradient,
                          std::array<float, 512>& out) const {
    constexpr float kNone = std::numeric_limits<float>::quiet_NaN();
    // The nodes around the leaf's voxels (at most 9 along each axis), gathered: their mean
    // distance and centroid, NaN where no band weighs on them.
    const openvdb::Coord lo = floorDiv(origin, m_);
    const openvdb::Coord n = floorDiv(origin.offsetBy(6 + m_), m_) - lo + openvdb::Coord(1);
    // The blocks they lie in: at most two along each axis, looked up once.
    std::array<const Block*, 8> blocks{};
    const openvdb::Coord first = blockOrigin(lo);
    for (int bx = 0; bx < 2; ++bx)
        for (int by = 0; by < 2; ++by)
            for (int bz = 0; bz < 2; ++bz) {
                const int b = blockOf(first.offsetBy(8 * bx, 8 * by, 8 * bz));
                // Only the blocks the z pass made hold the blur.
                if (b >= 0 && std::size_t(b) < pass_[2].size())
                    blocks[std::size_t(bx) * 4 + std::size_t(by) * 2 + std::size_t(bz)] =
                        &b_[std::size_t(b)];
            }
    std::array<std::array<float, 4>, 729> node;
    for (int x = 0; x < n.x(); ++x)
        for (int y = 0; y < n.y(); ++y)
            for (int z = 0; z < n.z(); ++z) {
                const openvdb::Coord local = lo.offsetBy(x, y, z) - first;
                auto& to = node[(std::size_t(x) * 9 + std::size_t(y)) * 9 + std::size_t(z)];
                to = {kNone, kNone, kNone, kNone};
                const int which = (local.x() >> 3) * 4 + (local.y() >> 3) * 2 + (local.z() >> 3);
                const Block* block = blocks[std::size_t(which)];
                if (!block) continue;
                const std::size_t at = offset(local.x() & 7, local.y() & 7, local.z() & 7);
                if (!(block->f[at] > 0.0f)) continue;
                for (std::size_t f = 0; f < 4; ++f)
                    to[f] = block->f[(f + 1) * 512 + at];
            }
    const float inv = 1.0f / float(m_);
    for (openvdb::Index i = 0; i < Leaf::SIZE; ++i) {
        if (!((which[i >> 6] >> (i & 63)) & 1)) continue;
        const openvdb::Coord x = origin + Leaf::offsetToLocalCoord(i);
        const openvdb::Coord k0 = floorDiv(x, m_);
        const openvdb::Coord o = x - times(k0, m_), local = k0 - lo;
        std::array<float, 4> sum{0.0f, 0.0f, 0.0f, 0.0f};
        for (int dx = 0; dx <= (o.x() > 0); ++dx) {
            const float wx = dx ? float(o.x()) * inv : float(m_ - o.x()) * inv;
            for (int dy = 0; dy <= (o.y() > 0); ++dy) {
                const float wy = dy ? float(o.y()) * inv : float(m_ - o.y()) * inv;
                for (int dz = 0; dz <= (o.z() > 0); ++dz) {
                    const float wz = dz ? float(o.z()) * inv : float(m_ - o.z()) * inv;
                    const int at = ((local.x() + dx) * 9 + local.y() + dy) * 9 + local.z() + dz;
                    const auto& v = node[std::size_t(at)];
                    const float w = wx * wy * wz;
                    for (std::size_t f = 0; f < 4; ++f)
                        sum[f] += w * v[f];
                }
            }
        }
        // u = mean - g . (centroid - x): each band voxel's distance carried to x along g.
        const openvdb::Coord rel = x - center_;
        const openvdb::Vec3f& g = gradient[i];
        out[i] = sum[0] - (g.x() * (sum[1] - float(rel.x())) + g.y() * (sum[2] - float(rel.y())) +
                           g.z() * (sum[3] - float(rel.z())));
    }
}

} // namespace sweepers
