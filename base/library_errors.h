#pragma once
// Exceptions of the libraries arview calls, caught where the input is known. A reader's own
// checks throw arview::Error naming the file; what a library throws past them (std::bad_alloc
// for a file too large for the memory left, std::length_error, std::filesystem's
// filesystem_error for a name too long or a folder that cannot be searched, OpenCV's
// cv::Exception, yaml-cpp's YAML::Exception, nlohmann-json's exceptions) reached app/cli/main.cpp
// as its bare text ("basic_string::_M_create", "filesystem error: status: File name too long").
// A reader's entry point runs its work through NamingInput, so that every failure is one of the
// reader's own errors whose message starts with the input.

#include <filesystem>
#include <new>
#include <string>
#include <utility>

#include "base/error.h"

namespace arview {

// read(), with any exception that is not an arview::Error turned into E("<source>: <why>").
template <class E, class F>
decltype(auto) NamingInput(const std::string& source, F&& read) {
  try {
    return std::forward<F>(read)();
  } catch (const Error&) {
    throw;  // ours: already names the input
  } catch (const std::bad_alloc&) {
    throw E(source + ": not enough memory to read it");
  } catch (const std::filesystem::filesystem_error& e) {
    throw E(source + ": " + e.code().message());
  } catch (const std::exception& e) {
    throw E(source + ": " + e.what());
  }
}

}  // namespace arview
