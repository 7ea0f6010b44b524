#pragma once
// The one error type of posed_eval. Evaluation is an offline, all-or-nothing computation on
// files a person named, so a problem ends it: the message says where (file:line) and what, and
// `posectl eval` turns it into exit code 2. Nothing here calls exit() or abort().

#include <stdexcept>
#include <string>

namespace posed::eval {

class EvalError : public std::runtime_error {
 public:
  explicit EvalError(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace posed::eval
