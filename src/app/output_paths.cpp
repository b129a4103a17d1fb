#include "app/output_paths.h"

#include <sys/stat.h>

#include <algorithm>
#include <filesystem>

#include "common/error.h"
#include "image/image_io.h"

namespace osr::app {

namespace fs = std::filesystem;

namespace {

bool statOf(const std::string& path, struct stat& st) { return ::stat(path.c_str(), &st) == 0; }

bool sameIdentity(const struct stat& a, const struct stat& b) {
  return a.st_dev == b.st_dev && a.st_ino == b.st_ino;
}

std::string lowerExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

}  // namespace

bool sameFile(const std::string& a, const std::string& b) {
  struct stat sa, sb;
  const bool ea = statOf(a, sa), eb = statOf(b, sb);
  if (ea && eb) return sameIdentity(sa, sb);
  // A path that does not exist yet (or a dangling link, which the write would replace) is the
  // same as another if it would be created in the same directory under the same name.
  const fs::path pa(a), pb(b);
  if (pa.filename() != pb.filename()) return false;
  struct stat da, db;
  const std::string dirA = pa.has_parent_path() ? pa.parent_path().string() : ".";
  const std::string dirB = pb.has_parent_path() ? pb.parent_path().string() : ".";
  return statOf(dirA, da) && statOf(dirB, db) && sameIdentity(da, db);
}

void checkOutputs(const std::vector<OutputFile>& outputs, const std::vector<NamedPath>& inputs) {
  for (size_t i = 0; i < outputs.size(); ++i) {
    const OutputFile& o = outputs[i];
    for (const NamedPath& in : inputs)
      if (sameFile(o.path, in.path))
        throw InputError(o.role + " " + o.path + ": is " + in.role +
                         (in.path == o.path ? "" : " (" + in.path + ")") +
                         ", which this render reads; refusing to overwrite it");
    for (size_t j = 0; j < i; ++j)
      if (sameFile(o.path, outputs[j].path))
        throw InputError(o.role + " " + o.path + ": is also the " + outputs[j].role +
                         " output (" + outputs[j].path + "); give each output its own file");
    const std::string ext = lowerExtension(o.path);
    if (ext != o.extension)
      throw InputError(o.role + " " + o.path + ": writes " + o.format + ", so the name must end in " +
                       o.extension + (ext.empty() ? "" : ", not " + ext));
    image::checkWritable(o.path);
  }
}

}  // namespace osr::app
