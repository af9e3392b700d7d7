// SPDX-License-Identifier: Apache-2.0
// The Gaussian of a narrow band's signed distance near its surface, at a cost that follows
// the band, not the Gaussian's volume.
//
// Convolving a signed distance d with the heat kernel of time t (a Gaussian of standard
// deviation sigma = sqrt(2 t)) moves its zero set by mean curvature for time t (Esedoglu,
// Ruuth and Tsai, "Diffusion generated motion using signed distance functions", J. Comput.
// Phys. 229, 2010): G * d = d + t Laplacian(d) + O(t^2), and the Laplacian of a distance is
// its level set's mean curvature (the sum of the principal curvatures). Bumps of wavenumber
// k fade by exp(-k^2 t), as under the flow.
//
// Two things make it cheap:
// - Only the band is read. The Gaussian's support reaches sigma beyond the band, where the
//   grid holds no distance; the average is taken over band voxels only, each extrapolated to
//   the point x asked for by the gradient g at x (Knutsson and Westin's normalized
//   convolution, "Normalized and differential convolution", CVPR 1993, with a linear model):
//       u(x) = sum_i G(x - i) (d_i + g . (x - i)) / sum_i G(x - i)
//            = mean(x) - g . (centroid(x) - x),
//   mean and centroid being the Gaussian-weighted averages of d_i and of i over the band.
//   The linear part of d cancels whatever the band's shape about x, so what remains is the
//   average of d's departure from its tangent plane at x: its curvature term.
// - The sums are smooth at the scale sigma, so they are taken on a lattice of spacing m
//   voxels (m about 1.1 sigma): each band voxel is splatted onto the 8 lattice nodes
//   around it with trilinear weights, the lattice is blurred by a separable sampled
//   Gaussian, and each voxel asked for reads the 8 nodes around it back (the splat, blur and
//   slice of Paris and Durand's bilateral grid, ECCV 2006). The splat and the slice each
//   blur by a variance of (m^2 - 1) / 6 voxels^2 on each axis, which the lattice's Gaussian
//   leaves out. The work is a few dozen operations per band voxel and a few hundred per
//   lattice node near the band, whose count stays the same as the voxels get finer.
//
// Every node and voxel is summed in one fixed order: the result is the same at any thread
// count, bit for bit.
#pragma once

#include <array>
#include <cstddef>
#include <unordered_map>
#include <vector>

#include "vdb/leaf_words.h"
#include "vdb/vdb.h"
#include "vdb/voxel_list.h"

namespace sweepers {

struct DistanceFilterStats {
    int spacing = 1;              // the lattice's spacing m, in voxels
    int radius = 0;               // the lattice blur's half-width, in nodes
    double latticeSigma = 0.0;    // its standard deviation, in nodes
    std::size_t inputLeaves = 0;  // leaves splatted (a leaf counted in each block it reaches)
    std::size_t blocks = 0;       // lattice blocks (8^3 nodes) splatted
    std::size_t outputBlocks = 0; // of which the voxels asked for read
    double work = 0.0;            // multiply-adds of the splat and blur, as planned
};

class DistanceFilter {
  public:
    using Leaf = Grid::TreeType::LeafNodeType;

    // sigma: the Gaussian's standard deviation, in voxels, at least kSmallestSigma (below it
    // the sampled Gaussian no longer has the continuous one's decay). center: a voxel near
    // the work, the origin of the offsets summed (so that they stay small in floats).
    DistanceFilter(const Grid& grid, double sigma, const openvdb::Coord& center);
    static constexpr double kSmallestSigma = 1.75;

    // The phases, in order. plan: the lattice blocks that the voxels `wanted` read and
    // those the blur reads for them, the band voxels (active, |d| below the background) of
    // `leaves` splatted into them, and the work the rest takes; nothing is allocated beyond
    // the block lists. `leaves` must hold the band within (radius + 2) spacing voxels of the
    // voxels wanted.
    void plan(const std::vector<const Leaf*>& leaves, const VoxelList& wanted);
    const DistanceFilterStats& stats() const { return stats_; }
    void splat();
    void blur();
    // The filtered distance u (in voxels) at the voxels `which` of the leaf at `origin`,
    // given the distance's gradient there (voxels per voxel): out[i] for each, NaN where the
    // lattice holds no band around it (no input leaf near it).
    void read(const openvdb::Coord& origin, const leafwords::Words& which,
              const std::array<openvdb::Vec3f, 512>& gradient, std::array<float, 512>& out) const;

  private:
    static constexpr int kFields = 5; // weight, weighted distance, weighted offset x, y, z
    struct Block {
        std::array<float, std::size_t(kFields) * 512> f; // field k at k * 512 + x * 64 + y * 8 + z
    };
    struct CoordHash {
        std::size_t operator()(const openvdb::Coord& c) const {
            return std::size_t(c.x()) * 73856093u ^ std::size_t(c.y()) * 19349663u ^
                   std::size_t(c.z()) * 83492791u;
        }
    };
    int blockOf(const openvdb::Coord& blockOrigin) const; // -1 where there is none
    int insertBlock(const openvdb::Coord& blockOrigin);
    void pass(int axis, const std::vector<int>& blocks, const std::vector<Block>& from,
              std::vector<Block>& to) const;

    const Grid& grid_;
    openvdb::Coord center_;
    int m_ = 1;
    std::vector<float> kernel_; // 2 radius + 1 weights, summing to 1
    std::vector<const Leaf*> leaves_;
    std::vector<openvdb::Coord> origin_; // each block's first node
    std::unordered_map<openvdb::Coord, int, CoordHash> index_;
    std::vector<std::array<int, 6>> neighbour_; // -x, +x, -y, +y, -z, +z (or -1)
    // The blocks each pass makes, along x, y and z: the z pass's are the first blocks, those
    // the voxels asked for read; each pass's include the next's and their neighbours.
    std::array<std::vector<int>, 3> pass_;
    std::vector<std::vector<int>> splatFrom_; // of each block: the leaves splatting into it
    std::vector<Block> a_, b_;                // the passes' two buffers; b_ at the end
    DistanceFilterStats stats_;
};

} // namespace sweepers
