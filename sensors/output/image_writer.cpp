// Atomic image and text file output with OpenImageIO: EXR (scene-linear float), PNG/TIFF (display).
#include "sensors/output/image_writer.h"

#include <OpenImageIO/imageio.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <memory>
#include <system_error>
#include <utility>

#include "scene/core/check.h"
#include "scene/core/error.h"

namespace seasense::sensors {

namespace fs = std::filesystem;

void ImageMetadata::Set(std::string name, MetadataValue value) {
    for (MetadataAttribute& attribute : attributes) {
        if (attribute.name == name) {
            attribute.value = std::move(value);
            return;
        }
    }
    attributes.push_back({std::move(name), std::move(value)});
}

const MetadataValue* ImageMetadata::Find(std::string_view name) const {
    for (const MetadataAttribute& attribute : attributes) {
        if (attribute.name == name) return &attribute.value;
    }
    return nullptr;
}

void ImageMetadata::SetCaptureTime(scene::UtcTime t) {
    // "YYYY-MM-DDThh:mm:ss.fffZ" → "YYYY:MM:DD hh:mm:ss".
    std::string text = scene::FormatIso8601(t).substr(0, 19);
    text[4] = ':';
    text[7] = ':';
    text[10] = ' ';
    Set("DateTime", std::move(text));
}

namespace {

// DateTime stored when the caller gives none: the Unix epoch, never the wall clock, so that
// the same input always gives the same bytes.
constexpr const char* kDefaultDateTime = "1970:01:01 00:00:00";

// Makes temporary names unique within this process; the pid makes them unique across
// processes writing into the same folder at the same time.
std::atomic<std::uint64_t> tempCounter{0};

std::string Quoted(const fs::path& path) { return "'" + path.string() + "'"; }

fs::path FolderOf(const fs::path& path) {
    fs::path folder = path.parent_path();
    return folder.empty() ? fs::path(".") : folder;
}

// Hidden file in the destination folder (rename is atomic only within one file system), with
// the random part before the extension so tools that look at the extension still see it.
fs::path TempPathFor(const fs::path& finalPath) {
    // Appended piece by piece: GCC 12 gives a false -Wrestrict for "." + std::string&&.
    std::string name = ".";
    name += finalPath.stem().string();
    name += ".tmp.";
    name += std::to_string(::getpid());
    name += '.';
    name += std::to_string(tempCounter.fetch_add(1));
    name += finalPath.extension().string();
    return finalPath.parent_path() / name;
}

void EnsureFolder(const fs::path& finalPath) {
    const fs::path folder = FolderOf(finalPath);
    std::error_code error;
    fs::create_directories(folder, error);
    if (!error && !fs::is_directory(folder, error) && !error) {
        error = std::make_error_code(std::errc::not_a_directory);
    }
    if (error) {
        throw RuntimeError("cannot write " + Quoted(finalPath) + ": cannot create output folder " +
                           Quoted(folder) + ": " + error.message());
    }
}

// Flushes the file's data to disk before the rename, so that after a crash the final name
// never refers to a file whose contents were not yet written.
void SyncFile(const fs::path& tempPath, const fs::path& finalPath) {
    const int fd = ::open(tempPath.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0 || ::fsync(fd) != 0) {
        const std::string reason = std::strerror(errno);
        if (fd >= 0) ::close(fd);
        throw RuntimeError("cannot write " + Quoted(finalPath) + ": cannot sync temporary file " +
                           Quoted(tempPath) + ": " + reason);
    }
    ::close(fd);
}

// Runs writeTemp(tempPath), then renames the temporary file over finalPath. On any failure
// the temporary file is removed and finalPath is left as it was.
template <typename WriteFn>
void WriteAtomically(const fs::path& finalPath, WriteFn&& writeTemp) {
    if (!finalPath.has_filename() || finalPath.filename() == "." || finalPath.filename() == "..") {
        throw InputError("output path " + Quoted(finalPath) + " does not name a file");
    }
    EnsureFolder(finalPath);
    const fs::path tempPath = TempPathFor(finalPath);
    try {
        writeTemp(tempPath);
        SyncFile(tempPath, finalPath);
        std::error_code error;
        fs::rename(tempPath, finalPath, error);
        if (error) {
            throw RuntimeError("cannot write " + Quoted(finalPath) +
                               ": cannot rename temporary file " + Quoted(tempPath) +
                               " to it: " + error.message());
        }
    } catch (...) {
        std::error_code ignored;
        fs::remove(tempPath, ignored);
        throw;
    }
}

void AddMetadata(OIIO::ImageSpec& spec, const ImageMetadata& metadata, const fs::path& finalPath) {
    if (!metadata.Find("DateTime")) spec.attribute("DateTime", kDefaultDateTime);
    for (const MetadataAttribute& attribute : metadata.attributes) {
        const std::string& name = attribute.name;
        if (name.empty()) {
            throw InputError("cannot write " + Quoted(finalPath) +
                             ": metadata attribute with an empty name");
        }
        const MetadataValue& value = attribute.value;
        if (const auto* s = std::get_if<std::string>(&value)) {
            spec.attribute(name, *s);
        } else if (const auto* i = std::get_if<int>(&value)) {
            spec.attribute(name, *i);
        } else if (const auto* f = std::get_if<float>(&value)) {
            spec.attribute(name, *f);
        } else if (const auto* array = std::get_if<std::vector<float>>(&value)) {
            if (array->empty()) {
                throw InputError("cannot write " + Quoted(finalPath) + ": metadata attribute '" +
                                 name + "' is an empty float array");
            }
            spec.attribute(name, OIIO::TypeDesc(OIIO::TypeDesc::FLOAT, int(array->size())),
                           array->data());
        } else if (const auto* v3 = std::get_if<Vector3f>(&value)) {
            spec.attribute(name, OIIO::TypeVector, v3->v.data());
        } else if (const auto* m3 = std::get_if<Matrix33f>(&value)) {
            spec.attribute(name, OIIO::TypeMatrix33, m3->m.data());
        } else if (const auto* m4 = std::get_if<Matrix44f>(&value)) {
            spec.attribute(name, OIIO::TypeMatrix44, m4->m.data());
        }
    }
}

// Writes one image with OIIO into tempPath; the format plugin is named explicitly, so the
// temporary file's name plays no part in choosing it.
void WriteWithOiio(const char* formatName, const fs::path& tempPath, const fs::path& finalPath,
                   const OIIO::ImageSpec& spec, OIIO::TypeDesc dataType, const void* data) {
    auto fail = [&](const std::string& oiioError) {
        return RuntimeError(
            "cannot write " + Quoted(finalPath) + " (temporary file " + Quoted(tempPath) +
            "): " + (oiioError.empty() ? std::string("unknown OpenImageIO error") : oiioError));
    };
    std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(formatName);
    if (!out) throw fail(OIIO::geterror());
    if (!out->open(tempPath.string(), spec)) throw fail(out->geterror());
    if (!out->write_image(dataType, data)) {
        const std::string error = out->geterror();
        out->close();
        throw fail(error);
    }
    if (!out->close()) throw fail(out->geterror());
}

void CheckDimensions(const fs::path& path, int width, int height, int channels, int maxChannels) {
    if (width <= 0 || height <= 0 || channels <= 0 || channels > maxChannels) {
        throw InputError("cannot write " + Quoted(path) + ": image size " + std::to_string(width) +
                         "x" + std::to_string(height) + "x" + std::to_string(channels) +
                         " is invalid, expected positive width and height and 1.." +
                         std::to_string(maxChannels) + " channels");
    }
}

std::vector<std::string> ExrChannelNames(const fs::path& path, int channels,
                                         const std::vector<std::string>& given) {
    if (!given.empty()) {
        if (int(given.size()) != channels) {
            throw InputError("cannot write " + Quoted(path) + ": " + std::to_string(given.size()) +
                             " channel names for " + std::to_string(channels) + " channels");
        }
        for (const std::string& name : given) {
            if (name.empty()) {
                throw InputError("cannot write " + Quoted(path) + ": empty channel name");
            }
        }
        return given;
    }
    switch (channels) {
        case 1:
            return {"Y"};
        case 2:
            return {"Y", "A"};
        case 3:
            return {"R", "G", "B"};
        case 4:
            return {"R", "G", "B", "A"};
        default:
            throw InputError("cannot write " + Quoted(path) + ": " + std::to_string(channels) +
                             " channels need explicit channel names");
    }
}

// OIIO plugin name for a display image, from the file extension.
const char* DisplayFormatFor(const fs::path& path) {
    std::string extension = path.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (extension == ".png") return "png";
    if (extension == ".tif" || extension == ".tiff") return "tiff";
    throw InputError("cannot write " + Quoted(path) + ": unsupported display image extension '" +
                     path.extension().string() + "', expected .png, .tif or .tiff");
}

void WriteDisplayImage(const fs::path& path, const void* pixels, size_t pixelCount,
                       OIIO::TypeDesc type, int width, int height, int channels,
                       const ImageMetadata& metadata) {
    const char* format = DisplayFormatFor(path);
    CheckDimensions(path, width, height, channels, 4);
    CHECK_MSG(pixelCount == size_t(width) * size_t(height) * size_t(channels),
              "display image buffer holds " << pixelCount << " values for " << width << "x"
                                            << height << "x" << channels);
    OIIO::ImageSpec spec(width, height, channels, type);
    if (std::string(format) == "tiff") spec.attribute("compression", "zip");
    // zlib level 1 instead of libpng's default 6: 2.4× faster on a 640×480 frame for ~1.6×
    // the bytes, which matters when five channels write every frame of a run. And every row
    // through the Sub filter (each byte minus the one a pixel to its left; PNG specification,
    // ISO/IEC 15948 §9.2) instead of libpng's per-row trial of all five filters: the trial cost
    // more than the compression (png_write_row 131 → 55 M instructions on the five-channel
    // demo's otw-center frame 120, 61 vs 136 M on its NVG frame), and its files were no smaller
    // (154 vs 166 kB; NVG 180 vs 186 kB; FLIR gray 179 vs 178 kB). OIIO's "png:filter" takes
    // libpng's filter mask, PNG_FILTER_SUB = 0x10 (png.h).
    if (std::string(format) == "png") {
        spec.attribute("png:compressionLevel", 1);
        spec.attribute("png:filter", 0x10);
    }
    AddMetadata(spec, metadata, path);
    WriteAtomically(path, [&](const fs::path& tempPath) {
        WriteWithOiio(format, tempPath, path, spec, type, pixels);
    });
}

}  // namespace

void WriteExr(const fs::path& path, const Image& image, const ImageMetadata& metadata,
              const ExrOptions& options) {
    constexpr int kMaxExrChannels = 1024;
    CheckDimensions(path, image.width, image.height, image.channels, kMaxExrChannels);
    CHECK_MSG(
        image.pixels.size() == size_t(image.width) * size_t(image.height) * size_t(image.channels),
        "image buffer holds " << image.pixels.size() << " values for " << image.width << "x"
                              << image.height << "x" << image.channels);
    const OIIO::TypeDesc fileType =
        options.pixelType == ExrPixelType::Half ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT;
    OIIO::ImageSpec spec(image.width, image.height, image.channels, fileType);
    spec.channelnames = ExrChannelNames(path, image.channels, options.channelNames);
    const auto alpha = std::find(spec.channelnames.begin(), spec.channelnames.end(), "A");
    spec.alpha_channel =
        alpha == spec.channelnames.end() ? -1 : int(alpha - spec.channelnames.begin());
    // Lossless, and the usual choice for rendered frames (OpenEXR file layout docs).
    spec.attribute("compression", "zip");
    AddMetadata(spec, metadata, path);
    WriteAtomically(path, [&](const fs::path& tempPath) {
        WriteWithOiio("openexr", tempPath, path, spec, OIIO::TypeDesc::FLOAT, image.pixels.data());
    });
}

void WriteDisplayImage8(const fs::path& path, std::span<const std::uint8_t> pixels, int width,
                        int height, int channels, const ImageMetadata& metadata) {
    WriteDisplayImage(path, pixels.data(), pixels.size(), OIIO::TypeDesc::UINT8, width, height,
                      channels, metadata);
}

void WriteDisplayImage16(const fs::path& path, std::span<const std::uint16_t> pixels, int width,
                         int height, int channels, const ImageMetadata& metadata) {
    WriteDisplayImage(path, pixels.data(), pixels.size(), OIIO::TypeDesc::UINT16, width, height,
                      channels, metadata);
}

void WriteTextFileAtomic(const fs::path& path, std::string_view text) {
    WriteAtomically(path, [&](const fs::path& tempPath) {
        std::ofstream out(tempPath, std::ios::binary | std::ios::trunc);
        if (!out) {
            throw RuntimeError("cannot write " + Quoted(path) + ": cannot create temporary file " +
                               Quoted(tempPath) + ": " + std::strerror(errno));
        }
        out.write(text.data(), std::streamsize(text.size()));
        out.close();
        if (!out) {
            throw RuntimeError("cannot write " + Quoted(path) + ": writing temporary file " +
                               Quoted(tempPath) + " failed: " + std::strerror(errno));
        }
    });
}

}  // namespace seasense::sensors
