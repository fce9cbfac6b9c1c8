#pragma once
/// @file
/// @brief XDMF (.xmf) description of the snapshots of a case file, so ParaView (XDMF readers) opens them as a
/// time series of surface meshes whose heavy data stay in the HDF5 file.

#include <filesystem>
#include <string>
#include <vector>

namespace capsim::io {

/// @brief One snapshot as seen by the XDMF file.
struct XdmfSnapshot {
  std::string group;  ///< HDF5 path of the snapshot group, e.g. "/snapshots/000003"
  double t = 0;
  long long num_nodes = 0;
  /// Node fields: dataset name (inside the group) and 1 or 3 components.
  std::vector<std::pair<std::string, int>> fields;
};

/// @brief The mesh topology shared by all snapshots.
struct XdmfTopologyRef {
  std::string dataset;        ///< e.g. "/mesh/connectivity_p2"
  std::string type;           ///< XDMF TopologyType: "Triangle_6" or "Triangle"
  int nodes_per_element = 6;  ///< 6 or 3
  long long num_elements = 0;
};

/// @brief The XML text of a temporal collection over `snapshots`, referencing datasets of `h5_name` (a file
/// name relative to the .xmf, which ParaView resolves from the .xmf's directory).
std::string xdmf_document(const std::string& h5_name, const XdmfTopologyRef& topology,
                          const std::vector<XdmfSnapshot>& snapshots);

}  // namespace capsim::io
