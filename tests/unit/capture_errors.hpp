// Test support: collects what goes through the runtime's error hook while in
// scope, instead of printing it.
#pragma once

#include <string>
#include <vector>

#include "sicm/runtime.h"

class CaptureErrors {
public:
  CaptureErrors() { previous_ = sicm_set_error_handler(&CaptureErrors::handle); }
  ~CaptureErrors() {
    sicm_set_error_handler(previous_);
    messages().clear();
    statuses().clear();
  }
  static std::vector<std::string> &messages() {
    static std::vector<std::string> m;
    return m;
  }
  static std::vector<int> &statuses() {
    static std::vector<int> s;
    return s;
  }

private:
  static void handle(const char *reason, int status) {
    messages().push_back(reason);
    statuses().push_back(status);
  }
  sicm_error_handler_t *previous_;
};
