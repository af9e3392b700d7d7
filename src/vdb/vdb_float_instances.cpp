// SPDX-License-Identifier: Apache-2.0
// The one instantiation of the FloatTree grid classes declared extern in vdb_instances.h (a
// source file per grid type, so that they compile in parallel).
#include "vdb/vdb_instances.h"

template class openvdb::tree::Tree<openvdb::FloatTree::RootNodeType>;
template class openvdb::Grid<openvdb::FloatTree>;
