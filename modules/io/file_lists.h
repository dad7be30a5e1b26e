// Lists of input files given as a directory or a glob (`selfcal detect --images DIR|GLOB`), and the key
// that matches an image to its pose file.
#pragma once

#include <string>
#include <vector>

#include "base/status.h"

namespace selfcal::io {

// The stem of a path: its file name without directory and last extension ("a/b/0.png" -> "0").
std::string FileStem(const std::string& path);

// What matches an image to its pose: the last run of decimal digits in the file name's stem, without
// leading zeros ("img_007.png" -> "7", "0.yaml" -> "0"); the whole stem when it has no digit.
std::string ImageKey(const std::string& path);

// The regular files of `spec`: every file directly in it whose name ends in one of `extensions`
// (lower-case, with the dot; compared case-insensitively) when `spec` is a directory, else the files
// matching the glob `spec` (any name). Sorted by ImageKey, numerically when both keys are numbers
// ("2" before "10"), then by path. ErrorCode::kInvalidInput naming `spec` and `what` ("images", "pose
// files") when nothing matches or the directory cannot be read.
Result<std::vector<std::string>> ListFiles(const std::string& spec, const std::vector<std::string>& extensions,
                                           const std::string& what);

// One pose of a folder-per-pose recording (`DIR/<id>/image.png` + `DIR/<id>/data.json`, as the kvasios
// Franka recorder stores them): the folder's name and its image and pose file.
struct PoseFolder {
  std::string id;         // the folder's name ("pose_03")
  std::string image;      // its one image file
  std::string pose_file;  // its one pose file (.json, .yaml or .yml)
};

// Whether `dir` is a folder-per-pose directory: a directory with subdirectories and no image file.
bool IsPoseFolderDirectory(const std::string& dir);

// Every subdirectory of `dir`, in the natural order of the folders' names (runs of digits by value: "pose_2"
// before "pose_10", and "s1_pose_11" before "s3_pose_00", so that the folders of two recordings copied into one
// stay in recording order), each with
// exactly one image file (ImageExtensions) and one pose file (PoseFileExtensions); a folder without either,
// or with two, is refused naming it (ErrorCode::kInvalidInput, every such folder listed). Files directly
// in `dir` (a recorder's own results) are not looked at.
Result<std::vector<PoseFolder>> ListPoseFolders(const std::string& dir);

// The extensions of per-image pose files: .yaml .yml .json.
const std::vector<std::string>& PoseFileExtensions();

// The extensions of the image files `ListFiles` takes from a directory: .png .jpg .jpeg .pgm .ppm .bmp
// .tif .tiff.
const std::vector<std::string>& ImageExtensions();

}  // namespace selfcal::io
