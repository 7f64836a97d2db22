#include "rmhb/sweep/sweep_file.h"

#include <hdf5.h>

#include <cmath>
#include <stdexcept>

namespace rmhb::sweep {
namespace {

using nlohmann::json;

// Closes an HDF5 handle when it goes out of scope.
class Handle {
 public:
  Handle(hid_t id, herr_t (*close)(hid_t), const std::string& what) : id_(id), close_(close) {
    if (id_ < 0) throw std::runtime_error("HDF5: cannot create " + what);
  }
  ~Handle() {
    if (id_ >= 0) close_(id_);
  }
  Handle(Handle&& other) noexcept : id_(other.id_), close_(other.close_) { other.id_ = -1; }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  operator hid_t() const { return id_; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

void Check(herr_t status, const std::string& what) {
  if (status < 0) throw std::runtime_error("HDF5: cannot write " + what);
}

// Object creation properties without modification times: the same content
// makes the same bytes.
Handle NoTimes(hid_t property_class) {
  Handle p(H5Pcreate(property_class), H5Pclose, "a property list");
  Check(H5Pset_obj_track_times(p, false), "a property list");
  return p;
}

Handle Group(hid_t parent, const std::string& name) {
  const Handle gcpl = NoTimes(H5P_GROUP_CREATE);
  return Handle(H5Gcreate2(parent, name.c_str(), H5P_DEFAULT, gcpl, H5P_DEFAULT), H5Gclose, name);
}

void Write(hid_t parent, const std::string& name, hid_t type, const std::vector<hsize_t>& dims,
           const void* data) {
  const Handle space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose, name);
  const Handle dcpl = NoTimes(H5P_DATASET_CREATE);
  const Handle set(H5Dcreate2(parent, name.c_str(), type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT), H5Dclose, name);
  hsize_t size = 1;
  for (hsize_t d : dims) size *= d;
  if (size > 0) Check(H5Dwrite(set, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), name);
}

void WriteDoubles(hid_t parent, const std::string& name, const std::vector<double>& v,
                  std::vector<hsize_t> dims = {}) {
  if (dims.empty()) dims = {v.size()};
  Write(parent, name, H5T_NATIVE_DOUBLE, dims, v.data());
}

void WriteLongs(hid_t parent, const std::string& name, const std::vector<long long>& v) {
  Write(parent, name, H5T_NATIVE_LLONG, {v.size()}, v.data());
}

Handle StringType() {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose, "a string type");
  Check(H5Tset_size(type, H5T_VARIABLE), "a string type");
  Check(H5Tset_cset(type, H5T_CSET_UTF8), "a string type");
  return type;
}

void WriteStrings(hid_t parent, const std::string& name, const std::vector<std::string>& v) {
  std::vector<const char*> pointers;
  for (const std::string& s : v) pointers.push_back(s.c_str());
  Write(parent, name, StringType(), {v.size()}, pointers.data());
}

void Attribute(hid_t object, const std::string& name, const std::string& value) {
  const Handle type = StringType();
  const Handle space(H5Screate(H5S_SCALAR), H5Sclose, name);
  const Handle attribute(H5Acreate2(object, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose, name);
  const char* text = value.c_str();
  Check(H5Awrite(attribute, type, &text), name);
}

void WriteGrid(hid_t file, const ParameterGrid& grid) {
  const Handle group = Group(file, "grid");
  for (const GridAxis& axis : grid.axes()) {
    std::vector<double> values;
    for (int i = 0; i < axis.count; ++i) values.push_back(axis.Value(i));
    WriteDoubles(group, axis.name, values);
  }
}

void WritePoints(hid_t file, const ParameterGrid& grid, const std::vector<json>& points) {
  std::vector<long long> index, count, first, solves, non_physical;
  std::vector<double> values;
  std::vector<std::string> status, message;
  long long row = 0;
  for (const json& p : points) {
    index.push_back(p.at("index").get<long long>());
    for (double v : p.at("values")) values.push_back(v);
    status.push_back(p.at("status").get<std::string>());
    message.push_back(p.at("message").get<std::string>());
    count.push_back(static_cast<long long>(p.at("solutions").size()));
    first.push_back(row);
    row += count.back();
    solves.push_back(p.at("solves").get<long long>());
    non_physical.push_back(p.at("non_physical").get<long long>());
  }
  const Handle group = Group(file, "points");
  WriteLongs(group, "index", index);
  WriteDoubles(group, "values", values, {points.size(), grid.axes().size()});
  WriteStrings(group, "status", status);
  WriteStrings(group, "message", message);
  WriteLongs(group, "solutions", count);
  WriteLongs(group, "first_solution", first);
  WriteLongs(group, "solves", solves);
  WriteLongs(group, "non_physical", non_physical);
}

void WriteSolutions(hid_t file, const std::vector<json>& points, const std::vector<std::string>& variables) {
  std::vector<long long> point;
  std::vector<double> frequencies, amplitude, residual, max_real_part, coefficients;
  std::vector<std::string> stability, route;
  hsize_t bases = 0, coefficients_per_variable = 0;
  for (const json& p : points)
    for (const json& s : p.at("solutions")) {
      point.push_back(p.at("index").get<long long>());
      bases = s.at("frequencies").size();
      for (double w : s.at("frequencies")) frequencies.push_back(w);
      amplitude.push_back(s.at("amplitude").get<double>());
      residual.push_back(s.at("residual").get<double>());
      max_real_part.push_back(s.at("max_real_part").get<double>());
      stability.push_back(s.at("stability").get<std::string>());
      route.push_back(s.at("route").get<std::string>());
      for (const json& row : s.at("coefficients")) {
        coefficients_per_variable = row.size();
        for (double c : row) coefficients.push_back(c);
      }
    }
  const Handle group = Group(file, "solutions");
  WriteLongs(group, "point", point);
  WriteDoubles(group, "frequencies", frequencies, {point.size(), bases});
  WriteDoubles(group, "amplitude", amplitude);
  WriteDoubles(group, "residual", residual);
  WriteDoubles(group, "max_real_part", max_real_part);
  WriteStrings(group, "stability", stability);
  WriteStrings(group, "route", route);
  WriteDoubles(group, "coefficients", coefficients, {point.size(), variables.size(), coefficients_per_variable});
  std::string names;
  for (const std::string& v : variables) names += (names.empty() ? "" : ",") + v;
  const Handle set(H5Dopen2(group, "coefficients", H5P_DEFAULT), H5Dclose, "coefficients");
  Attribute(set, "variables", names);
}

void WriteMap(hid_t file, const ParameterGrid& grid, const std::vector<json>& points) {
  std::vector<double> amplitude, count;
  for (const json& p : points) {
    double peak = NAN;
    for (const json& s : p.at("solutions"))
      peak = std::isnan(peak) ? s.at("amplitude").get<double>() : std::max(peak, s.at("amplitude").get<double>());
    amplitude.push_back(peak);
    count.push_back(static_cast<double>(p.at("solutions").size()));
  }
  std::vector<hsize_t> dims;  // C order, last index fastest: [n_last ... n_first]
  for (auto a = grid.axes().rbegin(); a != grid.axes().rend(); ++a) dims.push_back(a->count);
  const Handle group = Group(file, "map");
  WriteDoubles(group, "amplitude", amplitude, dims);
  WriteDoubles(group, "count", count, dims);
}

}  // namespace

void WriteSweepFile(const std::string& path, const ParameterGrid& grid, const SweepFileInfo& info,
                    const std::vector<json>& points) {
  if (static_cast<long>(points.size()) != grid.size())
    throw std::invalid_argument("WriteSweepFile: one record per grid point expected");
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors become exceptions, not stderr noise
  const Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, "a property list");
  Check(H5Pset_libver_bounds(fapl, H5F_LIBVER_EARLIEST, H5F_LIBVER_V18), path);
  const Handle fcpl = NoTimes(H5P_FILE_CREATE);
  const Handle file(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, fcpl, fapl), H5Fclose, path);
  Attribute(file, "format", "rmhb sweep 1");
  Attribute(file, "software", info.software);
  Attribute(file, "model", info.model);
  Attribute(file, "model_text", info.model_text);
  Attribute(file, "parameters", info.parameters);
  Attribute(file, "options", info.options);
  Attribute(file, "fingerprint", info.fingerprint);
  std::string axes;
  for (const GridAxis& a : grid.axes())
    axes += (axes.empty() ? "" : " ") + a.name + "=" + json(a.from).dump() + ":" + json(a.to).dump() + ":" +
            std::to_string(a.count);
  Attribute(file, "grid", axes);
  WriteGrid(file, grid);
  WritePoints(file, grid, points);
  WriteSolutions(file, points, info.variables);
  WriteMap(file, grid, points);
}

}  // namespace rmhb::sweep
