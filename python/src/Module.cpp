// tessera._tessera: the Python module's native part. It marshals Python
// values into session::Session calls and hands frames back as numpy arrays;
// every check, loop and default is the library's (python/tessera/__init__.py
// holds the Pythonic surface). Settings cross as the session's one JSON
// schema (session::Settings::toJson/fromJson), so they are validated there.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "tessera/core/Error.h"
#include "tessera/core/SliceImage.h"
#include "tessera/core/TransferFunction.h"
#include "tessera/core/Volume.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/io/VolumeWriter.h"
#include "tessera/io/ZarrArray.h"
#include "tessera/io/ZarrStore.h"
#include "tessera/io/ZarrWriter.h"
#include "tessera/lod/VolumeSource.h"
#include "tessera/session/Convert.h"
#include "tessera/session/Session.h"
#include "tessera/session/VolumeInfo.h"
#include "tessera/viewer/CameraController.h"

namespace py = pybind11;
using tessera::Image;
using tessera::InputError;
using tessera::ScalarType;
using tessera::Volume;
using tessera::session::OpenOptions;

namespace {

// A volume as Python holds it: a spec opened by the session when it renders
// (a file, folder, store or URL, read lazily), or voxels in memory (a file
// read whole by load(), or a numpy array borrowed without a copy).
struct VolumeHandle {
  std::string spec;
  OpenOptions options;
  std::shared_ptr<Volume> volume;
  std::string name;

  const Volume& inCore() {
    if (!volume) {
      py::gil_scoped_release unlocked;
      volume = std::make_shared<Volume>(tessera::readVolume(
          spec, {.dicomSeries = options.series, .time = options.time, .channel = options.channel}));
    }
    return *volume;
  }
};

ScalarType scalarTypeOf(const std::string& dtype) {
  if (dtype == "u8") return ScalarType::U8;
  if (dtype == "u16") return ScalarType::U16;
  if (dtype == "i16") return ScalarType::I16;
  if (dtype == "f32") return ScalarType::F32;
  throw InputError("dtype " + dtype + ": Tessera renders u8, u16, i16 and f32 voxels");
}

// The numpy array's own buffer, borrowed: the volume's voxels are the
// array's memory, and the array stays alive (a reference held, released
// under the GIL) while any volume refers to it.
std::shared_ptr<VolumeHandle> borrowArray(py::buffer array, std::array<int, 3> dims,
                                          const std::string& dtype,
                                          const std::vector<std::vector<double>>& affine,
                                          const std::string& name) {
  py::buffer_info info = array.request(/*writable=*/false);
  const ScalarType type = scalarTypeOf(dtype);
  if (static_cast<std::size_t>(info.itemsize) != tessera::bytesPerVoxel(type)) {
    throw InputError(name + ": items of " + std::to_string(info.itemsize) + " bytes are no " +
                     dtype);
  }
  auto* keep = new py::object(array);
  std::shared_ptr<const void> lender(info.ptr, [keep](const void*) {
    if (Py_IsInitialized()) {
      py::gil_scoped_acquire locked;
      delete keep;
    }
  });
  auto* bytes = static_cast<std::byte*>(info.ptr);
  const std::size_t size = static_cast<std::size_t>(info.size) * info.itemsize;
  Volume v =
      Volume::borrow({dims[0], dims[1], dims[2]}, type, {bytes, size}, std::move(lender), name);
  if (affine.size() != 4) throw InputError(name + ": affine: expected 4 rows");
  glm::dmat4 m(1.0);
  for (int r = 0; r < 4; ++r) {
    if (affine[r].size() != 4) throw InputError(name + ": affine: expected 4 columns");
    for (int c = 0; c < 4; ++c) m[c][r] = affine[r][c];
  }
  v.setIndexToWorld(m);
  v.setGeometrySource("numpy array (affine given to from_array)");
  v.setDescription(name);
  auto h = std::make_shared<VolumeHandle>();
  h->volume = std::make_shared<Volume>(std::move(v));
  h->name = name;
  return h;
}

py::array_t<std::uint8_t> imageArray(Image image) {
  auto* rgba = new std::vector<std::uint8_t>(std::move(image.rgba()));
  py::capsule owner(rgba, [](void* p) { delete static_cast<std::vector<std::uint8_t>*>(p); });
  const py::ssize_t h = image.height(), w = image.width();
  return py::array_t<std::uint8_t>({h, w, py::ssize_t{4}}, {w * 4, py::ssize_t{4}, py::ssize_t{1}},
                                   rgba->data(), owner);
}

// One session on its own headless device, whose EGL context is current on
// the thread that made the session: calls come from that thread (another
// thread's call is refused with a GpuError saying so, as EGL would refuse
// it), one at a time (a lock serialises them); sessions made on different
// threads render in parallel.
class PySession {
 public:
  explicit PySession(const std::string& profile) {
    py::gil_scoped_release unlocked;
    session_ = std::make_unique<tessera::session::Session>(profile);
  }

  void open(VolumeHandle& v, const std::string& region, const std::string& level) {
    Use use(*this);
    if (v.volume && region.empty()) {
      session_->setVolume(v.volume, v.name.empty() ? v.spec : v.name);
      return;
    }
    if (v.spec.empty()) {
      throw InputError(
          "region applies to a volume opened from a file, store or URL; slice the array instead");
    }
    OpenOptions o = v.options;
    o.region = region;
    o.level = level.empty() ? "native" : level;
    session_->open(v.spec, o);
  }

  std::string settings() const { return session_->currentSettings().toJson().dump(); }
  // `tfDefault`: the user named no TF, so that a volume opened later gets
  // its modality's default (session/ModalityDefault.h) as the CLI's does.
  void setSettings(const std::string& json, bool tfDefault) {
    Use use(*this);
    tessera::session::Settings s =
        tessera::session::Settings::fromJson(nlohmann::json::parse(json));
    s.tfIsDefault = tfDefault;
    session_->setSettings(std::move(s));
  }
  std::string defaultNote() const { return session_->defaultNote(); }

  py::array_t<std::uint8_t> render(int width, int height) {
    Image image;
    {
      Use use(*this);
      image = session_->render(width, height);
    }
    return imageArray(std::move(image));
  }

  py::array_t<std::uint8_t> renderReference(int width, int height) {
    Image image;
    {
      Use use(*this);
      image = session_->renderReference(width, height);
    }
    return imageArray(std::move(image));
  }

  // Slice `index` normal to index axis `axis` (core/SliceImage.h: the
  // radiological convention `tessera slice` draws), grey over the window or
  // in the TF's colours.
  py::array_t<std::uint8_t> slice(int axis, int index, std::optional<std::pair<double, double>> w,
                                  const std::string& tfJson) {
    Image image;
    {
      Use use(*this);
      if (axis < 0 || axis > 2)
        throw InputError("axis " + std::to_string(axis) + ": expected 0, 1 or 2");
      const Volume& v = session_->volume();
      const tessera::ValueRange window = w ? tessera::ValueRange{w->first, w->second} : v.window();
      std::optional<tessera::TransferFunction> tf;
      if (!tfJson.empty()) tf = tessera::TransferFunction::fromJson(tfJson, "slice tf");
      image = tessera::sliceImage(v, tessera::sliceFrame(v.direction(), axis), index, window,
                                  tf ? &*tf : nullptr);
    }
    return imageArray(std::move(image));
  }

  // A run as `tessera render --repeat N --rotate D [--reference]` makes it:
  // the first frame and what the run measured.
  std::pair<py::array_t<std::uint8_t>, py::dict> run(int width, int height, int repeat,
                                                     double rotate, bool reference) {
    tessera::session::RenderResult r;
    {
      Use use(*this);
      tessera::session::RenderRequest req;
      req.settings = session_->settings();
      req.width = width;
      req.height = height;
      req.repeat = repeat;
      req.rotateDeg = rotate;
      req.reference = reference;
      r = session_->run(req);
    }
    py::dict d;
    d["frame_ms"] = r.frameMs;
    d["prepare_ms"] = r.prepareMs;
    d["layout"] = r.layout;
    d["layout_reason"] = r.layoutReason;
    d["texture_bytes"] = r.textureBytes;
    d["rendered_dims"] = std::make_tuple(r.renderedDims.x, r.renderedDims.y, r.renderedDims.z);
    if (r.psnrDb) d["psnr_db"] = *r.psnrDb;
    if (r.ssim) d["ssim"] = *r.ssim;
    return {imageArray(std::move(r.first)), d};
  }

  // A pointer drag of (dx, dy) pixels (y down) on the frame, as the
  // viewers' CameraController turns it into an orbit: the widget's drag.
  void orbit(double dx, double dy) {
    Use use(*this);
    tessera::session::Settings s = session_->currentSettings();
    tessera::viewer::CameraController controller(s.camera);
    controller.pointerDown(0, {0.0, 0.0});
    controller.pointerMove(0, {dx, dy});
    session_->setSettings(std::move(s));
  }

  std::string state() const { return session_->state().dump(); }
  std::string volumeName() const { return session_->name(); }
  bool streamed() const { return session_->streamed(); }
  std::string deviceText() const {
    const auto& d = session_->device();
    return d.profile.name + " (" + d.profile.note + ")";
  }

 private:
  // While a call runs: the GIL released, the session locked, its context current.
  struct Use {
    explicit Use(PySession& s) : lock(s.mutex_) {
      if (std::this_thread::get_id() != s.thread_) {
        throw tessera::GpuError(
            "this Session's GL context is current on the thread that made it; make one Session "
            "per thread (EGL makes a context current on one thread at a time)");
      }
      s.session_->device().context->makeCurrent();
    }
    py::gil_scoped_release unlocked;
    std::lock_guard<std::mutex> lock;
  };
  std::unique_ptr<tessera::session::Session> session_;
  std::thread::id thread_ = std::this_thread::get_id();
  std::mutex mutex_;
};

std::string info(VolumeHandle& v) {
  const Volume& volume = v.inCore();
  py::gil_scoped_release unlocked;
  return tessera::session::volumeInfo(v.spec.empty() ? v.name : v.spec, volume, v.options.time,
                                      v.options.channel)
      .dump();
}

// `tessera convert` for one volume: cropped and downsampled as asked, then
// an OME-Zarr store (its pyramid and chunks as the CLI writes them) or any
// format the registry writes (session/Convert.h, shared with the CLI).
std::vector<std::string> convert(VolumeHandle& v, const std::string& out,
                                 const tessera::session::ConvertRequest& request) {
  // Checked before anything is read, so that a typo fails at once.
  const tessera::OmeZarrWriteOptions z = tessera::session::zarrWriteOptions(request);
  const Volume& volume = v.inCore();
  py::gil_scoped_release unlocked;
  const bool changes = !request.crop.empty() || !request.downsample.empty();
  const Volume changed = changes ? tessera::session::cropAndDownsample(volume, request) : Volume();
  const Volume& written = changes ? changed : volume;
  if (tessera::isOmeZarrName(out)) {
    tessera::writeOmeZarr(written, out, z);
  } else {
    tessera::writeVolume(written, out);
  }
  return tessera::writeLossNotes(written, out);
}

std::string tfJson(const std::string& presetOrFileOrJson) {
  const std::string& s = presetOrFileOrJson;
  const bool json = !s.empty() && s.front() == '{';
  return (json ? tessera::TransferFunction::fromJson(s, "tf")
               : tessera::TransferFunction::fromPresetOrFile(s))
      .toJson();
}

}  // namespace

PYBIND11_MODULE(_tessera, m) {
  m.doc() = "Tessera's native module; use the package `tessera` (python/tessera/__init__.py).";
  // The library's errors, with its messages: input (ValueError), a host or
  // GPU budget (MemoryError), the GL/EGL driver (RuntimeError).
  static py::exception<tessera::InputError> inputError(m, "InputError", PyExc_ValueError);
  static py::exception<tessera::BudgetError> budgetError(m, "BudgetError", PyExc_MemoryError);
  static py::exception<tessera::GpuError> gpuError(m, "GpuError", PyExc_RuntimeError);
  static py::exception<tessera::Error> otherError(m, "Error", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const tessera::InputError& e) {
      inputError(e.what());
    } catch (const tessera::BudgetError& e) {
      budgetError(e.what());
    } catch (const tessera::GpuError& e) {
      gpuError(e.what());
    } catch (const tessera::Error& e) {
      otherError(e.what());
    } catch (const nlohmann::json::exception& e) {
      inputError((std::string("JSON: ") + e.what()).c_str());
    }
  });

  py::class_<VolumeHandle, std::shared_ptr<VolumeHandle>>(m, "VolumeHandle")
      .def_readonly("spec", &VolumeHandle::spec)
      .def_readonly("name", &VolumeHandle::name)
      .def_property_readonly("in_core", [](const VolumeHandle& v) { return v.volume != nullptr; })
      .def("load", [](VolumeHandle& v) { v.inCore(); })
      .def_property_readonly("dims",
                             [](VolumeHandle& v) {
                               const glm::ivec3 d = v.inCore().dims();
                               return std::make_tuple(d.x, d.y, d.z);
                             })
      .def_property_readonly(
          "dtype", [](VolumeHandle& v) { return std::string(scalarTypeName(v.inCore().type())); })
      .def_property_readonly("affine",
                             [](VolumeHandle& v) {
                               const glm::dmat4 a = v.inCore().indexToWorld();
                               std::vector<std::vector<double>> rows(4, std::vector<double>(4));
                               for (int r = 0; r < 4; ++r)
                                 for (int c = 0; c < 4; ++c) rows[r][c] = a[c][r];
                               return rows;
                             })
      .def_property_readonly("voxel_address",
                             [](VolumeHandle& v) {
                               return reinterpret_cast<std::uintptr_t>(v.inCore().bytes().data());
                             })
      .def_property_readonly("borrowed",
                             [](VolumeHandle& v) { return v.volume && v.volume->borrowsVoxels(); })
      .def("set_window", [](VolumeHandle& v, double lo, double hi) {
        v.inCore();
        v.volume->setWindow({lo, hi});
      });

  m.def(
      "open_spec",
      [](const std::string& spec, const std::string& series, int time, int channel) {
        auto h = std::make_shared<VolumeHandle>();
        h->spec = spec;
        h->name = spec;
        h->options.series = series;
        h->options.time = time;
        h->options.channel = channel;
        return h;
      },
      py::arg("spec"), py::arg("series") = "", py::arg("time") = 0, py::arg("channel") = 0);
  m.def("borrow_array", &borrowArray, py::arg("array"), py::arg("dims"), py::arg("dtype"),
        py::arg("affine"), py::arg("name") = "array");
  m.def("info", &info);
  m.def(
      "convert",
      [](VolumeHandle& v, const std::string& out, const std::string& chunk,
         const std::string& levels, const std::string& compressor, const std::string& crop,
         const std::string& downsample, int zarrFormat, int shard,
         const std::string& pyramidFactors) {
        return convert(v, out,
                       {.crop = crop,
                        .downsample = downsample,
                        .chunk = chunk,
                        .levels = levels,
                        .compressor = compressor,
                        .zarrFormat = zarrFormat,
                        .shard = shard,
                        .pyramidFactors = pyramidFactors});
      },
      py::arg("volume"), py::arg("out"), py::arg("chunk") = "64", py::arg("levels") = "auto",
      py::arg("compressor") = "zstd", py::arg("crop") = "", py::arg("downsample") = "",
      py::arg("zarr_format") = 2, py::arg("shard") = 0, py::arg("pyramid_factors") = "2,2,2");
  m.def("tf_json", &tfJson);
  m.def("tf_presets", &tessera::TransferFunction::presetNames);
  m.attr("orbit_degrees_per_pixel") = tessera::viewer::CameraController::kDegreesPerPixel;

  py::class_<PySession>(m, "SessionCore")
      .def(py::init<const std::string&>(), py::arg("profile") = "native")
      .def("open", &PySession::open, py::arg("volume"), py::arg("region") = "",
           py::arg("level") = "")
      .def("settings", &PySession::settings)
      .def("set_settings", &PySession::setSettings, py::arg("json"), py::arg("tf_default") = false)
      .def_property_readonly("default_note", &PySession::defaultNote)
      .def("render", &PySession::render)
      .def("render_reference", &PySession::renderReference)
      .def("slice", &PySession::slice, py::arg("axis"), py::arg("index"), py::arg("window"),
           py::arg("tf") = "")
      .def("run", &PySession::run, py::arg("width"), py::arg("height"), py::arg("repeat") = 1,
           py::arg("rotate") = 0.0, py::arg("reference") = false)
      .def("orbit", &PySession::orbit, py::arg("dx"), py::arg("dy"))
      .def("state", &PySession::state)
      .def_property_readonly("volume_name", &PySession::volumeName)
      .def_property_readonly("streamed", &PySession::streamed)
      .def_property_readonly("device", &PySession::deviceText);
}
