// SPDX-License-Identifier: Apache-2.0
// The OpenVDB grid classes the program uses, instantiated once (vdb_*_instances.cpp) instead
// of in every source file that makes or copies a grid. Tree and Grid are class templates with
// virtual members: a source that constructed one instantiated, optimized and compiled every
// virtual member (node counts, reads and writes, copies...), whether it called them or not.
// Declared extern here, they are compiled once; the compiler still sees their bodies, to
// inline them. Compiling the unused members in every source made the sanitizer build several
// times slower. The shared precompiled header starts with this header, so every source from
// the level-set layer up sees the declarations.
#pragma once

#include <openvdb/openvdb.h>

extern template class openvdb::tree::Tree<openvdb::FloatTree::RootNodeType>;
extern template class openvdb::Grid<openvdb::FloatTree>;
extern template class openvdb::tree::Tree<openvdb::MaskTree::RootNodeType>;
extern template class openvdb::Grid<openvdb::MaskTree>;
extern template class openvdb::tree::Tree<openvdb::Vec3STree::RootNodeType>;
extern template class openvdb::Grid<openvdb::Vec3STree>;
