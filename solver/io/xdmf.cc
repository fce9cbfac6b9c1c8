#include "solver/io/xdmf.h"

#include <sstream>

namespace capsim::io {

std::string xdmf_document(const std::string& h5_name, const XdmfTopologyRef& topology,
                          const std::vector<XdmfSnapshot>& snapshots) {
  std::ostringstream x;
  x.precision(17);
  x << "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n<Xdmf Version=\"3.0\">\n <Domain>\n"
    << "  <Grid Name=\"capsule\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (const auto& s : snapshots) {
    x << "   <Grid Name=\"" << s.group.substr(s.group.rfind('/') + 1) << "\" GridType=\"Uniform\">\n"
      << "    <Time Value=\"" << s.t << "\"/>\n"
      << "    <Topology TopologyType=\"" << topology.type << "\" NumberOfElements=\"" << topology.num_elements
      << "\">\n     <DataItem Dimensions=\"" << topology.num_elements << " " << topology.nodes_per_element
      << "\" NumberType=\"Int\" Precision=\"4\" Format=\"HDF\">" << h5_name << ":" << topology.dataset
      << "</DataItem>\n    </Topology>\n"
      << "    <Geometry GeometryType=\"XYZ\">\n     <DataItem Dimensions=\"" << s.num_nodes
      << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << h5_name << ":" << s.group
      << "/positions</DataItem>\n    </Geometry>\n";
    for (const auto& [name, comps] : s.fields) {
      x << "    <Attribute Name=\"" << name << "\" AttributeType=\"" << (comps == 3 ? "Vector" : "Scalar")
        << "\" Center=\"Node\">\n     <DataItem Dimensions=\"" << s.num_nodes << (comps == 3 ? " 3" : "")
        << "\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << h5_name << ":" << s.group << "/" << name
        << "</DataItem>\n    </Attribute>\n";
    }
    x << "   </Grid>\n";
  }
  x << "  </Grid>\n </Domain>\n</Xdmf>\n";
  return x.str();
}

}  // namespace capsim::io
