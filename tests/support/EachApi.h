#pragma once
// Tests that check one property on ES 3.0 and on ES 2.0: a suite derives
// from EachApi and is instantiated with
//   INSTANTIATE_TEST_SUITE_P(Api, Suite, test::kEveryApi, test::apiParamName);
// so each case runs twice, named .../gles3 and .../gles2.
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "support/GpuTestContext.h"
#include "tessera/gpu/GlContext.h"

namespace tessera::test {

class EachApi : public ::testing::TestWithParam<gpu::ApiLevel> {
 protected:
  // A context of this case's level, made on first use (see ApiContext). The
  // fixture outlives the test body, so the body's GL objects go first.
  gpu::GlContext& context() {
    if (!context_) context_.emplace(GetParam());
    return context_->get();
  }

 private:
  std::optional<ApiContext> context_;
};

inline const auto kEveryApi = ::testing::Values(gpu::ApiLevel::Gles3, gpu::ApiLevel::Gles2);

inline std::string apiParamName(const ::testing::TestParamInfo<gpu::ApiLevel>& info) {
  return apiName(info.param);
}

}  // namespace tessera::test
