// The browser's Inflater (io/Inflater.h): the page loads pako
// (frontends/web/package.json, copied into the site as pako_inflate.min.js), and each
// step runs it synchronously through JavaScript (InflaterPako.js), while
// the readers' chunked, budget-checked decoding goes on as natively.
#include <algorithm>
#include <array>

#include "io/Inflater.h"

// frontends/web/src/InflaterPako.js (linked with --js-library).
extern "C" {
int tessera_pako_open();
int tessera_pako_step(int id, const void* in, int inSize, void* out, int outSize, int* info,
                      char* error, int errorSize);
void tessera_pako_close(int id);
}

namespace tessera::io_detail {

namespace {

class PakoInflater final : public Inflater {
 public:
  PakoInflater() : id_(tessera_pako_open()) {}
  ~PakoInflater() override {
    if (id_ != 0) tessera_pako_close(id_);
  }
  PakoInflater(const PakoInflater&) = delete;
  PakoInflater& operator=(const PakoInflater&) = delete;

  Step inflate(std::span<const std::byte> in, std::span<std::byte> out) override {
    Step step;
    if (id_ == 0) {
      step.error = "pako (pako_inflate.min.js) is not loaded by the page";
      return step;
    }
    std::array<int, 3> info{};
    std::array<char, 256> error{};
    step.produced = static_cast<std::size_t>(tessera_pako_step(
        id_, in.data(), static_cast<int>(std::min<std::size_t>(in.size(), 1 << 30)), out.data(),
        static_cast<int>(std::min<std::size_t>(out.size(), 1 << 30)), info.data(), error.data(),
        static_cast<int>(error.size())));
    step.consumed = static_cast<std::size_t>(info[0]);
    step.ended = info[1] != 0;
    if (info[2] != 0) step.error = error.data();
    return step;
  }

 private:
  int id_;
};

}  // namespace

std::unique_ptr<Inflater> Inflater::create() {
  return std::make_unique<PakoInflater>();
}

}  // namespace tessera::io_detail
