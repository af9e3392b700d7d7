// SPDX-License-Identifier: Apache-2.0
// The one instantiation of the Vec3STree grid classes declared extern in vdb_instances.h (a
// source file per grid type, so that they compile in parallel).
#include "vdb/vdb_instances.h"

template class openvdb::tree::Tree<openvdb::Vec3STree::RootNodeType>;
template class openvdb::Grid<openvdb::Vec3STree>;
