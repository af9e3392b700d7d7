// SPDX-License-Identifier: Apache-2.0
// A box of leaves, every slot holding the index of a leaf in a list (or a mark) or -1: a
// leaf's neighbour is an array read, not a search or a hash lookup. Positions are in leaves
// (origin / 8). The mask dilation and the renormalization's domain find neighbouring leaves
// this way, and the mesher marks the leaves to mesh again, where the leaves fill enough of
// their box.
#pragma once

#include <cstddef>
#include <vector>

#include <openvdb/math/Coord.h>

namespace sweepers {

// A box of leaves is worth its table up to this many slots per leaf in it, plus a few
// thousand: a brush's band fills a few percent of its box.
constexpr std::size_t kSlotsPerLeaf = 64, kFewSlots = 1 << 15;

class LeafBox {
  public:
    LeafBox(const openvdb::Coord& lo, const openvdb::Coord& hi)
        : lo_(lo), n_(hi - lo + openvdb::Coord(1)),
          index_(std::size_t(n_.x()) * std::size_t(n_.y()) * std::size_t(n_.z()), -1) {}
    // The slot of position c, which lies in the box.
    int& at(const openvdb::Coord& c) { return index_[slot(c)]; }
    // The list index of the leaf at position c (-1: none, or outside the box).
    int get(const openvdb::Coord& c) const {
        const openvdb::Coord d = c - lo_;
        if (d.x() < 0 || d.y() < 0 || d.z() < 0 || d.x() >= n_.x() || d.y() >= n_.y() ||
            d.z() >= n_.z())
            return -1;
        return index_[slot(c)];
    }

  private:
    std::size_t slot(const openvdb::Coord& c) const {
        const openvdb::Coord d = c - lo_;
        return (std::size_t(d.x()) * std::size_t(n_.y()) + std::size_t(d.y())) *
                   std::size_t(n_.z()) +
               std::size_t(d.z());
    }
    openvdb::Coord lo_, n_;
    std::vector<int> index_;
};

} // namespace sweepers
