#pragma once
// The size of one SIFT descriptor, in one place: Map::descriptors' columns (map.h), the map file's
// records (map_file.cpp), the descriptor index (descriptor_index.cpp) and COLMAP's database
// (mapping/colmap_database.cpp, colmap_model.cpp).

namespace arview::map {

inline constexpr int kDescriptorSize = 128;  // bytes: uint8 SIFT in COLMAP's convention

}  // namespace arview::map
