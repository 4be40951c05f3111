// Atomic image and text file output: EXR (scene-linear float) and TIFF (display) with OpenImageIO,
// PNG (display) with our own encoder.
#include "sensors/output/image_writer.h"

#include <OpenImageIO/imageio.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>
#include <memory>
#include <optional>
#include <system_error>
#include <utility>

#include "scene/core/check.h"
#include "scene/core/error.h"
#include "sensors/output/png_encoder.h"

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

// Throws InputError (without the file name) for an attribute no format can store: an empty
// name or an empty float array.
void CheckAttribute(const MetadataAttribute& attribute) {
    if (attribute.name.empty()) throw InputError("metadata attribute with an empty name");
    const auto* array = std::get_if<std::vector<float>>(&attribute.value);
    if (array && array->empty()) {
        throw InputError("metadata attribute '" + attribute.name + "' is an empty float array");
    }
}

void AddMetadata(OIIO::ImageSpec& spec, const ImageMetadata& metadata, const fs::path& finalPath) {
    if (!metadata.Find("DateTime")) spec.attribute("DateTime", kDefaultDateTime);
    for (const MetadataAttribute& attribute : metadata.attributes) {
        try {
            CheckAttribute(attribute);
        } catch (const InputError& e) {
            throw InputError("cannot write " + Quoted(finalPath) + ": " + e.what());
        }
        const std::string& name = attribute.name;
        const MetadataValue& value = attribute.value;
        if (const auto* s = std::get_if<std::string>(&value)) {
            spec.attribute(name, *s);
        } else if (const auto* i = std::get_if<int>(&value)) {
            spec.attribute(name, *i);
        } else if (const auto* f = std::get_if<float>(&value)) {
            spec.attribute(name, *f);
        } else if (const auto* array = std::get_if<std::vector<float>>(&value)) {
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

// Format of a display image, from the file extension: "png" (png_encoder.h) or "tiff" (the
// OIIO plugin's name).
const char* DisplayFormatFor(const fs::path& path) {
    std::string extension = path.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (extension == ".png") return "png";
    if (extension == ".tif" || extension == ".tiff") return "tiff";
    throw InputError("cannot write " + Quoted(path) + ": unsupported display image extension '" +
                     path.extension().string() + "', expected .png, .tif or .tiff");
}

// Writes `bytes` into a new file at tempPath, checking every step.
void WriteFileBytes(const fs::path& tempPath, const fs::path& finalPath,
                    std::span<const std::uint8_t> bytes) {
    const int fd = ::open(tempPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) {
        throw RuntimeError("cannot write " + Quoted(finalPath) + ": cannot create temporary file " +
                           Quoted(tempPath) + ": " + std::strerror(errno));
    }
    for (std::size_t done = 0; done < bytes.size();) {
        const ssize_t written = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (written < 0 && errno == EINTR) continue;
        if (written <= 0) {
            const std::string reason = written < 0 ? std::strerror(errno) : "nothing written";
            ::close(fd);
            throw RuntimeError("cannot write " + Quoted(finalPath) + ": writing temporary file " +
                               Quoted(tempPath) + " failed: " + reason);
        }
        done += std::size_t(written);
    }
    if (::close(fd) != 0) {
        throw RuntimeError("cannot write " + Quoted(finalPath) + ": closing temporary file " +
                           Quoted(tempPath) + " failed: " + std::strerror(errno));
    }
}

// "YYYY:MM:DD hh:mm:ss" (the DateTime form) as tIME fields, or nothing if `text` is not in
// that form or a field is out of range.
std::optional<PngTime> PngTimeOf(const std::string& text) {
    constexpr std::string_view kForm = "dddd:dd:dd dd:dd:dd";
    if (text.size() != kForm.size()) return std::nullopt;
    for (std::size_t i = 0; i < kForm.size(); ++i) {
        const bool digit = std::isdigit(static_cast<unsigned char>(text[i])) != 0;
        if (kForm[i] == 'd' ? !digit : text[i] != kForm[i]) return std::nullopt;
    }
    const auto field = [&](std::size_t at, std::size_t digits) {
        int value = 0;
        for (std::size_t i = at; i < at + digits; ++i) value = value * 10 + (text[i] - '0');
        return value;
    };
    const PngTime t{field(0, 4),  field(5, 2),  field(8, 2),
                    field(11, 2), field(14, 2), field(17, 2)};
    if (!PngTimeIsValid(t)) return std::nullopt;
    return t;
}

void AppendNumber(std::string& out, float value) {
    char buffer[32];
    // Shortest form that reads back as the same float.
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
    out.append(buffer, result.ptr);
}

void AppendNumbers(std::string& out, std::span<const float> values) {
    for (std::size_t i = 0; i < values.size(); ++i) {
        if (i > 0) out += ", ";
        AppendNumber(out, values[i]);
    }
}

// A metadata value as PNG text: strings as they are; numbers in the shortest form that reads
// back as the same value; arrays, vectors and matrices (row by row) as their numbers separated
// by ", ", as OIIO prints them (oiiotool --info -v).
std::string PngTextOf(const MetadataValue& value) {
    std::string text;
    if (const auto* s = std::get_if<std::string>(&value)) {
        text = *s;
    } else if (const auto* i = std::get_if<int>(&value)) {
        text = std::to_string(*i);
    } else if (const auto* f = std::get_if<float>(&value)) {
        AppendNumber(text, *f);
    } else if (const auto* array = std::get_if<std::vector<float>>(&value)) {
        AppendNumbers(text, *array);
    } else if (const auto* v3 = std::get_if<Vector3f>(&value)) {
        AppendNumbers(text, v3->v);
    } else if (const auto* m3 = std::get_if<Matrix33f>(&value)) {
        AppendNumbers(text, m3->m);
    } else if (const auto* m4 = std::get_if<Matrix44f>(&value)) {
        AppendNumbers(text, m4->m);
    }
    return text;
}

// The PNG metadata of `metadata`, stored as OIIO's PNG writer stored it: DateTime (the Unix
// epoch if absent) in the tIME chunk, and a tEXt chunk for every other attribute, in order,
// under its own name, except that ImageDescription, Artist and DocumentName take the keywords
// PNG defines for them (§11.3.4.2: Description, Author, Title), which OIIO's reader maps back.
// OIIO stored string attributes only; the others are stored here as text (PngTextOf), so the
// PNG records what the EXR does. Throws InputError (without the file name) for an attribute
// that cannot be stored.
PngInfo PngInfoFor(const ImageMetadata& metadata) {
    PngInfo info;
    const MetadataValue* dateTime = metadata.Find("DateTime");
    const auto* dateText = dateTime ? std::get_if<std::string>(dateTime) : nullptr;
    info.time =
        dateTime ? (dateText ? PngTimeOf(*dateText) : std::nullopt) : PngTimeOf(kDefaultDateTime);
    for (const MetadataAttribute& attribute : metadata.attributes) {
        CheckAttribute(attribute);
        const std::string& name = attribute.name;
        // A DateTime not in the form tIME holds is kept as text rather than lost.
        if (name == "DateTime" && info.time) continue;
        std::string keyword = name;
        if (std::holds_alternative<std::string>(attribute.value)) {
            if (name == "ImageDescription") keyword = "Description";
            if (name == "Artist") keyword = "Author";
            if (name == "DocumentName") keyword = "Title";
        }
        info.text.push_back({std::move(keyword), PngTextOf(attribute.value)});
    }
    CheckPngInfo(info);
    return info;
}

// PNGs are encoded here (png_encoder.h) rather than through OIIO and libpng, because the
// five-channel demo writes five of them every frame. Every row goes through the Sub filter
// (each byte minus the one a pixel to its left; PNG specification §9.2) instead of libpng's
// per-row trial of all five filters: the trial cost more than the compression (png_write_row
// 131 → 55 M instructions on the demo's otw-center frame 120 at zlib level 1) and its files
// were no smaller. The rows are compressed in one call by libdeflate at level 1 instead of by
// zlib at level 1 through libpng (level 1 rather than the usual 6: with zlib 2.4× faster on a
// 640×480 frame for ~1.6× the bytes). On the demo's frame 120 the PNG costs 24 M instructions
// instead of 55 M for otw-center, 26 instead of 62 M for nvg and 15 instead of 41 M for flir
// (gray), and the files are 127 instead of 153 kB, 156 instead of 180 kB and 169 instead of 179 kB.
// Lossless either way: the pixels are the same.
template <typename Sample>
void WritePng(const fs::path& path, std::span<const Sample> pixels, int width, int height,
              int channels, const ImageMetadata& metadata) {
    std::vector<std::uint8_t> png;
    try {
        png = EncodePng(pixels, width, height, channels, PngInfoFor(metadata));
    } catch (const InputError& e) {
        throw InputError("cannot write " + Quoted(path) + ": " + e.what());
    } catch (const RuntimeError& e) {
        throw RuntimeError("cannot write " + Quoted(path) + ": " + e.what());
    }
    WriteAtomically(path, [&](const fs::path& tempPath) { WriteFileBytes(tempPath, path, png); });
}

template <typename Sample>
void WriteDisplayImage(const fs::path& path, std::span<const Sample> pixels, int width, int height,
                       int channels, const ImageMetadata& metadata) {
    const char* format = DisplayFormatFor(path);
    CheckDimensions(path, width, height, channels, 4);
    CHECK_MSG(pixels.size() == size_t(width) * size_t(height) * size_t(channels),
              "display image buffer holds " << pixels.size() << " values for " << width << "x"
                                            << height << "x" << channels);
    if (std::string_view(format) == "png") {
        WritePng(path, pixels, width, height, channels, metadata);
        return;
    }
    const OIIO::TypeDesc type = OIIO::BaseTypeFromC<Sample>::value;
    OIIO::ImageSpec spec(width, height, channels, type);
    spec.attribute("compression", "zip");
    AddMetadata(spec, metadata, path);
    WriteAtomically(path, [&](const fs::path& tempPath) {
        WriteWithOiio(format, tempPath, path, spec, type, pixels.data());
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
    WriteDisplayImage(path, pixels, width, height, channels, metadata);
}

void WriteDisplayImage16(const fs::path& path, std::span<const std::uint16_t> pixels, int width,
                         int height, int channels, const ImageMetadata& metadata) {
    WriteDisplayImage(path, pixels, width, height, channels, metadata);
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
