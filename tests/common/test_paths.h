// Paths for every test, with or without a device: test data, reference scenes, scratch folders.
#pragma once
#include <filesystem>
#include <string>

namespace osr::test {

// Path of a file of the checkout, e.g. sourcePath("tools"): under $OSR_SOURCE_DIR when that is
// set (test executables carried to a machine beside a copy of the checkout, as for the GPU runs
// of docs/device_notes.md), else under the checkout this build was configured from.
std::string sourcePath(const std::string& name);
// Path of a file under tests/data.
std::string dataPath(const std::string& name);
// A fresh-or-existing scratch folder under the system temp dir, unique to this process and
// `tag` (the test file's name), so parallel CTest runs never share one.
std::filesystem::path tempDir(const std::string& tag);

// A named pipe (FIFO) with no writer, `name` in tempDir(tag): an input path that a loader
// must refuse without opening it (open() would block forever).
std::string makeFifo(const std::string& tag, const std::string& name);

// Path of a reference scene file, e.g. referencePath("cornell/cornell.gltf").
std::string referencePath(const std::string& name);

}  // namespace osr::test
