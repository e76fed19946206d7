#pragma once
// One VTK XML unstructured-grid piece written as ASCII (shared by the snapshot writers of vtk.cpp
// and the orientation-class grids of micro_output.cpp).
#include <fmt/format.h>

#include <cstdint>
#include <string>
#include <vector>

#include "core/types.hpp"

namespace grainlab::io {

// Accumulates the arrays of one VTK XML unstructured-grid piece (ASCII, readable by ParaView,
// VTK and meshio).
class VtuPiece {
 public:
  static constexpr std::uint8_t kVertex = 1, kLine = 3, kPolygon = 7, kQuad = 9, kHexahedron = 12;  // VTK cell types

  void points(const std::vector<Vec3>& p) { points_ = p; }
  void cell(const std::vector<std::int64_t>& nodes, std::uint8_t vtkType) {
    for (auto n : nodes) connectivity_.push_back(n);
    offsets_.push_back(static_cast<std::int64_t>(connectivity_.size()));
    types_.push_back(vtkType);
  }
  void pointScalar(const std::string& name, const std::vector<double>& v) { pointData_ += array(name, v, 1); }
  void pointVector(const std::string& name, const std::vector<Vec3>& v) { pointData_ += array(name, flatten(v), 3); }
  // A 3x3 tensor per point, row-major (ParaView's Tensor Glyph filter draws it as an ellipsoid).
  void pointTensor(const std::string& name, const std::vector<Mat3>& v) {
    std::vector<double> flat;
    flat.reserve(9 * v.size());
    for (const Mat3& m : v)
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) flat.push_back(m(r, c));
    pointData_ += array(name, flat, 9);
  }
  void cellScalar(const std::string& name, const std::vector<double>& v) { cellData_ += array(name, v, 1); }
  void cellVector(const std::string& name, const std::vector<Vec3>& v) { cellData_ += array(name, flatten(v), 3); }

  std::string text() const {
    std::string s = "<?xml version=\"1.0\"?>\n"
                    "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
                    "<UnstructuredGrid>\n";
    s += fmt::format("<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", points_.size(), types_.size());
    s += "<PointData>\n" + pointData_ + "</PointData>\n<CellData>\n" + cellData_ + "</CellData>\n";
    s += array("Points", flatten(points_), 3, "<Points>\n", "</Points>\n");
    s += "<Cells>\n";
    s += "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n" + join(connectivity_) + "</DataArray>\n";
    s += "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n" + join(offsets_) + "</DataArray>\n";
    std::vector<std::int64_t> types(types_.begin(), types_.end());
    s += "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n" + join(types) + "</DataArray>\n";
    s += "</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
    return s;
  }

 private:
  static std::vector<double> flatten(const std::vector<Vec3>& v) {
    std::vector<double> out;
    out.reserve(3 * v.size());
    for (const Vec3& x : v) out.insert(out.end(), {x[0], x[1], x[2]});
    return out;
  }
  static std::string join(const std::vector<std::int64_t>& v) {
    std::string s;
    for (auto x : v) s += fmt::format("{} ", x);
    return s + "\n";
  }
  static std::string array(const std::string& name, const std::vector<double>& v, int components,
                           const std::string& open = "", const std::string& close = "") {
    std::string s = open + fmt::format("<DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"ascii\">\n",
                                       name, components);
    for (std::size_t i = 0; i < v.size(); ++i) s += fmt::format("{:.9g}{}", v[i], (i + 1) % components ? " " : "\n");
    return s + "</DataArray>\n" + close;
  }

  std::vector<Vec3> points_;
  std::vector<std::int64_t> connectivity_, offsets_;
  std::vector<std::uint8_t> types_;
  std::string pointData_, cellData_;
};

// A .pvd collection indexing KIND_0000.vtu, KIND_0001.vtu, ... by their time values (ParaView
// shows `labels` as the time, e.g. the axial strain).
inline std::string pvdCollection(const std::string& kind, const std::vector<double>& labels) {
  std::string s = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n";
  for (std::size_t i = 0; i < labels.size(); ++i)
    s += fmt::format("<DataSet timestep=\"{:.9g}\" group=\"\" part=\"0\" file=\"{}_{:04d}.vtu\"/>\n", labels[i], kind, i);
  return s + "</Collection>\n</VTKFile>\n";
}

}  // namespace grainlab::io
