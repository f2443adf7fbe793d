// OpenImageIO 2.4 behind the C interface of oiio.h: the only C++ in the project, built as the
// module libgodrays_oiio.so that oiio.c loads on first use (oiio_module.h says why). Its one
// exported function hands oiio.c the table of the functions below; every body is wrapped in
// try/catch(...) so that no exception reaches C code, and the program is called only through
// the host table.
extern "C" {
#include "common/memlimit.h"
#include "common/outfile.h"
#include "common/status.h"
#include "image/exr.h"
}
#include "image/oiio_module.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

#include <OpenImageIO/imageio.h>

namespace {

// The program's functions (gr_oiio_module_open keeps them).
const gr_oiio_host *host = nullptr;

// One line: OpenImageIO messages may span several lines.
std::string one_line(std::string s)
{
    for (char &ch : s)
        if (ch == '\n' || ch == '\r') ch = ' ';
    while (!s.empty() && s.back() == ' ') s.pop_back();
    return s.empty() ? std::string("unknown OpenImageIO error") : s;
}

gr_status fail(gr_error *err, gr_status st, const char *path, const char *what, const std::string &why)
{
    return host->fail(err, st, "%s: %s: %s", path, what, one_line(why).c_str());
}

// The sRGB EOTF as IEC 61966-2-1 writes it (the inverse of image/png.c's OETF).
float srgb_decode(float c)
{
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

// Redirects stderr (fd 2) into a temporary file while it lives: libpng's default handlers
// print a line of their own ("libpng error: IHDR: CRC error") where the CLI promises one. The
// text is taken into the error message; the capture is used by the CLI's single thread that
// reads inputs, never while a render runs.
class StderrCapture {
  public:
    explicit StderrCapture(bool on = true)
    {
        if (!on) return;
        std::fflush(stderr);
        f_ = std::tmpfile();
        if (f_) saved_ = dup(2);
        if (saved_ < 0 || dup2(fileno(f_), 2) < 0) restore();
    }
    ~StderrCapture() { restore(); }
    // Restores stderr; returns what was captured as one line (libpng's "libpng error: " dropped).
    std::string take()
    {
        if (!f_ || saved_ < 0) return std::string();
        std::fflush(stderr);
        std::string text;
        std::rewind(f_);
        char buf[512];
        size_t n;
        while ((n = std::fread(buf, 1, sizeof buf, f_)) > 0 && text.size() < 2048) text.append(buf, n);
        restore();
        text = text.empty() ? text : one_line(text);
        const std::string pre = "libpng error: ";
        if (text.compare(0, pre.size(), pre) == 0) text = "libpng: " + text.substr(pre.size());
        return text;
    }

  private:
    void restore()
    {
        if (saved_ >= 0) {
            std::fflush(stderr);
            dup2(saved_, 2);
            close(saved_);
            saved_ = -1;
        }
        if (f_) {
            std::fclose(f_);
            f_ = nullptr;
        }
    }
    FILE *f_ = nullptr;
    int saved_ = -1;
};

// The chunk list of a PNG file against its size, before libpng sees it: libpng allocates what a
// chunk's length field claims (a 2 KB file whose tEXt chunk claimed 2 GB took 2 GB of memory,
// found by fuzzing), so a chunk that does not fit the file is refused first. A file that is not
// a PNG at all is left to the reader's own message.
gr_status check_png_chunks(const char *path, gr_error *err, bool *complete = nullptr)
{
    if (complete) *complete = false;
    FILE *f = std::fopen(path, "rb");
    if (!f) return GR_OK; // the reader reports it
    unsigned char b[8];
    gr_status st = GR_OK;
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    if (std::fseek(f, 0, SEEK_END) == 0) {
        const long long size = std::ftell(f);
        std::rewind(f);
        if (size > 0 && std::fread(b, 1, 8, f) == 8 && !std::memcmp(b, sig, 8)) {
            long long pos = 8;
            while (pos + 8 <= size && std::fread(b, 1, 8, f) == 8) {
                const unsigned long long len = (unsigned long long)b[0] << 24 | (unsigned long long)b[1] << 16 |
                                               (unsigned long long)b[2] << 8 | b[3];
                char type[5] = {(char)b[4], (char)b[5], (char)b[6], (char)b[7], 0};
                for (char &c : type)
                    if (c && (c < 'A' || (c > 'Z' && c < 'a') || c > 'z')) c = '?';
                if ((long long)len > size - pos - 12) {
                    st = host->fail(err, GR_E_INPUT, "%s: PNG chunk '%s' at byte %lld claims %llu bytes, past the end of the "
                                 "%lld-byte file", path, type, pos, len, size);
                    break;
                }
                if (!std::memcmp(type, "IEND", 4)) {
                    if (complete) *complete = true;
                    break;
                }
                pos += 12 + (long long)len;
                if (std::fseek(f, (long)(len + 4), SEEK_CUR) != 0) break;
            }
        }
    }
    std::fclose(f);
    return st;
}

// Appends libpng's captured text to an OpenImageIO message unless it already says it.
void add_lib_text(std::string &why, const std::string &lib)
{
    const std::string core = lib.compare(0, 8, "libpng: ") == 0 ? lib.substr(8) : lib;
    if (!core.empty() && why.find(core) == std::string::npos) why += " (" + lib + ")";
}

// Writes w x h x nc pixels of type `type` to a temporary file (common/outfile) in the format
// that `path`'s extension names, reads it back (OpenImageIO's PNG writer does not report a
// failed write: a full disk left a 0-byte or truncated file), then renames it over `path`.
gr_status write_via_temp(const char *path, const OIIO::ImageSpec &spec, OIIO::TypeDesc type,
                         const void *data, gr_error *err)
{
    auto out = OIIO::ImageOutput::create(path);
    if (!out) return fail(err, GR_E_INPUT, path, "no writer for this file type", OIIO::geterror());
    gr_outfile of;
    gr_status st = host->outfile_begin(&of, path, err);
    if (st != GR_OK) return st;
    const std::string tmp = of.tmp;
    const std::string format = out->format_name();
    OIIO::ImageSpec wspec = spec;
    // PNG: zlib level 4 rather than OpenImageIO's 6: a report's PNGs in a third of the time
    // for 9 % more bytes (docs/report.md)
    if (format == "png" && !wspec.find_attribute("png:compressionLevel")) wspec.attribute("png:compressionLevel", 4);
    if (!out->open(tmp, wspec)) {
        st = fail(err, GR_E_IO, path, "cannot create file", out->geterror());
    } else {
        if (!out->write_image(type, data))
            st = fail(err, GR_E_IO, path, "writing pixels", out->geterror());
        if (!out->close() && st == GR_OK)
            st = fail(err, GR_E_IO, path, "closing file", out->geterror());
    }
    out.reset();
    bool png_done = false;
    if (st == GR_OK && format == "png") {
        // PNG: the chunk list must end with IEND inside the file (read back through libpng, a
        // truncated file longjmps out of OpenImageIO's reader and leaks)
        gr_error perr;
        if (check_png_chunks(tmp.c_str(), &perr, &png_done) != GR_OK || !png_done)
            st = host->fail(err, GR_E_IO, "%s: cannot write: the file written is incomplete (is the disk full?)", path);
        png_done = true;
    }
    if (st == GR_OK && !png_done) {
        StderrCapture quiet; // a reader's own line about the truncated file: the message says it
        auto in = OIIO::ImageInput::create(format);
        std::vector<unsigned char> back(spec.image_bytes());
        OIIO::ImageSpec got;
        if (!in || !in->open(tmp, got) || got.width != spec.width || got.height != spec.height ||
            !in->read_image(0, 0, 0, spec.nchannels, spec.format, back.data()))
            st = host->fail(err, GR_E_IO, "%s: cannot write: the file written does not read back whole (is the disk full?)",
                         path);
        if (in) {
            in->close();
            (void)in->geterror();
        }
        (void)OIIO::geterror();
    }
    if (st == GR_OK) return host->outfile_commit(&of, 1, err);
    host->outfile_abort(&of);
    return st;
}

bool image_ok(const gr_image *img)
{
    return img && img->pixels && img->width > 0 && img->height > 0 && img->nchannels > 0 &&
           img->nchannels <= GR_IMAGE_MAX_CHANNELS;
}

gr_status exception_status(gr_error *err, const char *path, const char *what)
{
    try {
        throw;
    } catch (const std::bad_alloc &) {
        return host->fail(err, GR_E_NOMEM, "%s: %s: out of memory", path ? path : "(null)", what);
    } catch (const std::exception &e) {
        return host->fail(err, GR_E_RUNTIME, "%s: %s: %s", path ? path : "(null)", what, one_line(e.what()).c_str());
    } catch (...) {
        return host->fail(err, GR_E_RUNTIME, "%s: %s: unknown exception", path ? path : "(null)", what);
    }
}

// The formats the image reader takes, by file extension (docs/images.md): those a renderer or
// an image tool writes for comparisons. Anything else is refused before it is opened.
#define READ_EXTS ".exr, .png, .tif/.tiff, .hdr, .jpg/.jpeg, .bmp, .ppm/.pgm/.pnm/.pbm, .tga"
const char *read_format(const char *path)
{
    static const char *const table[][2] = {
        {"exr", "openexr"}, {"png", "png"}, {"tif", "tiff"}, {"tiff", "tiff"}, {"hdr", "hdr"}, {"jpg", "jpeg"},
        {"jpeg", "jpeg"}, {"bmp", "bmp"}, {"ppm", "pnm"}, {"pgm", "pnm"}, {"pnm", "pnm"}, {"pbm", "pnm"},
        {"tga", "targa"}};
    const char *dot = std::strrchr(path, '.'), *slash = std::strrchr(path, '/');
    if (!dot || (slash && slash > dot)) return nullptr;
    for (const auto &e : table)
        if (OIIO::Strutil::iequals(dot + 1, e[0])) return e[1];
    return nullptr;
}

// What a header declares against the file and the memory limit, before anything is allocated
// (issue 31: a 222-byte TIFF declaring 8192 x 8192 pixels took 1.2 GB and was read as zeros).
// No codec the reader takes expands its data by more than about 1:2700 (deflate's limit is
// 1:1032, PNG, TIFF and EXR ZIP; LZW's about 1:2730; JPEG, RLE and PackBits far less), so a
// file whose decoded samples are over 4096 times its size cannot hold them.
gr_status check_declared_size(const char *path, const OIIO::ImageSpec &spec, gr_error *err)
{
    const double decoded = static_cast<double>(spec.image_bytes());
    struct stat sb;
    if (stat(path, &sb) == 0 && decoded > 4096.0 * static_cast<double>(sb.st_size) + 65536.0)
        return host->fail(err, GR_E_INPUT, "%s: declares %d x %d pixels of %d channel%s (%.0f bytes of samples) in a %lld-byte "
                       "file: no image format compresses that much; damaged or forged", path, spec.width, spec.height,
                       spec.nchannels, spec.nchannels == 1 ? "" : "s", decoded, static_cast<long long>(sb.st_size));
    char what[300], detail[160];
    std::snprintf(what, sizeof what, "reading %s", path);
    std::snprintf(detail, sizeof detail, "%d x %d pixels x %d channel(s) as float, and the file's samples", spec.width,
                  spec.height, spec.nchannels);
    return host->memlimit_check(what, 4.0 * spec.image_pixels() * spec.nchannels + decoded, detail, err);
}

} // namespace

static const char *oiio_version(void)
{
    try {
        // The runtime library's version (not the header's), e.g. 20407 -> "2.4.7".
        static const std::string v = [] {
            int n = OIIO::openimageio_version();
            return std::to_string(n / 10000) + "." + std::to_string(n / 100 % 100) + "." + std::to_string(n % 100);
        }();
        return v.c_str();
    } catch (...) {
        return "unknown";
    }
}

// Pixels with a channel other than alpha at 1, the top code of an integer file read as
// code / max (before any decoding).
static long long count_top_code(const gr_image *img, int alpha)
{
    const size_t n = static_cast<size_t>(img->width) * static_cast<size_t>(img->height);
    const size_t nc = static_cast<size_t>(img->nchannels);
    long long top = 0;
    for (size_t p = 0; p < n; p++) {
        for (size_t c = 0; c < nc; c++) {
            if (static_cast<int>(c) != alpha && img->pixels[p * nc + c] >= 1.0f) {
                top++;
                break;
            }
        }
    }
    return top;
}

static gr_status oiio_read_info(const char *path, int linearize, gr_image **out, gr_oiio_info *info,
                                       gr_error *err)
{
    if (info) std::memset(info, 0, sizeof *info);
    if (out) *out = nullptr;
    if (!path || !path[0] || !out) return host->fail(err, GR_E_USAGE, "image read: no input path or output");
    gr_image *img = nullptr;
    gr_status reg = host->check_regular_input(path, err); // a FIFO blocks, /dev/zero spins
    if (reg != GR_OK) return reg;
    const char *format = read_format(path);
    if (!format) {
        FILE *f = std::fopen(path, "rb"); // a missing file says so first
        if (!f) return host->fail(err, GR_E_IO, "%s: cannot open: %s", path, std::strerror(errno));
        std::fclose(f);
        return host->fail(err, GR_E_INPUT, "%s: not a supported image file name (the reader takes %s)", path, READ_EXTS);
    }
    // EXR files pass the project's checks first (image/exr.c: data window and chunk table
    // against the file, before anything is allocated): OpenEXR's C++ reader behind
    // OpenImageIO rebuilt a huge offset table for seconds from a 2.5 KB file.
    if (!std::strcmp(format, "openexr")) {
        gr_status est = host->exr_check(path, err);
        if (est != GR_OK) return est;
    }
    // libpng prints its own line ("IHDR: CRC error"): kept for the message (PNG only, so
    // that anything else a reader prints, a sanitizer's report included, stays visible)
    if (!std::strcmp(format, "png")) {
        gr_status pst = check_png_chunks(path, err);
        if (pst != GR_OK) return pst;
    }
    StderrCapture cap(!std::strcmp(format, "png"));
    try {
        // The reader of the extension's format only: OpenImageIO's fallback would try every
        // reader it has (IFF spun forever on /dev/zero; JPEG-2000 starts threads per try).
        auto in = OIIO::ImageInput::create(format);
        OIIO::ImageSpec opened;
        if (in && !in->open(path, opened)) {
            std::string why = in->geterror();
            in.reset();
            (void)OIIO::geterror();
            if (why.empty()) why = "not a valid file of this format";
            FILE *f = std::fopen(path, "rb");
            if (!f) return host->fail(err, GR_E_IO, "%s: cannot open: %s", path, std::strerror(errno));
            std::fclose(f);
            const std::string lib = cap.take();
            add_lib_text(why, lib);
            return fail(err, GR_E_INPUT, path, "cannot read as an image", why);
        }
        if (!in) {
            std::string why = OIIO::geterror();
            const std::string lib = cap.take();
            add_lib_text(why, lib);
            // A missing or unreadable file is an I/O error; anything else is bad input.
            FILE *f = std::fopen(path, "rb");
            if (!f) return host->fail(err, GR_E_IO, "%s: cannot open: %s", path, std::strerror(errno));
            std::fclose(f);
            return fail(err, GR_E_INPUT, path, "cannot read as an image", why);
        }
        const OIIO::ImageSpec &spec = in->spec();
        if (spec.deep) return host->fail(err, GR_E_INPUT, "%s: deep images are not supported", path);
        if (spec.depth > 1) return host->fail(err, GR_E_INPUT, "%s: volume images are not supported", path);
        const int nc = spec.nchannels;
        gr_status cst = host->image_check_size(path, spec.width, spec.height, nc, err);
        if (cst != GR_OK) return cst;
        if (nc <= 0 || nc > GR_IMAGE_MAX_CHANNELS)
            return host->fail(err, GR_E_INPUT, "%s: %d channels (1 to %d supported)", path, nc, GR_IMAGE_MAX_CHANNELS);
        cst = check_declared_size(path, spec, err);
        if (cst != GR_OK) return cst;
        static const char *const rgba[4] = {"R", "G", "B", "A"};
        std::vector<std::string> names(static_cast<size_t>(nc));
        std::vector<const char *> cnames(static_cast<size_t>(nc));
        for (int c = 0; c < nc; c++) {
            std::string n = c < static_cast<int>(spec.channelnames.size()) ? spec.channelnames[static_cast<size_t>(c)] : "";
            if (n.empty()) n = c < 4 ? rgba[c] : "c" + std::to_string(c);
            if (n.size() >= GR_CHANNEL_NAME_MAX)
                return host->fail(err, GR_E_INPUT, "%s: channel %d name '%s' is longer than %d characters", path, c, n.c_str(), GR_CHANNEL_NAME_MAX - 1);
            names[static_cast<size_t>(c)] = n;
        }
        for (int c = 0; c < nc; c++) cnames[static_cast<size_t>(c)] = names[static_cast<size_t>(c)].c_str();
        img = host->image_create(spec.width, spec.height, nc, cnames.data());
        if (!img) return host->fail(err, GR_E_NOMEM, "%s: cannot allocate %d x %d x %d image", path, spec.width, spec.height, nc);
        // Scanline files are read in their own sample type and converted here: read_image
        // allocates a 64 MB buffer on every call in OpenImageIO 2.4 (tiled files still use it).
        const bool native = spec.channelformats.empty() && spec.tile_width == 0;
        std::vector<unsigned char> raw(native ? spec.image_bytes() : 0);
        bool read_ok = native ? in->read_native_scanlines(0, 0, spec.y, spec.y + spec.height, spec.z, raw.data())
                              : in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, img->pixels);
        if (read_ok && native)
            read_ok = OIIO::convert_pixel_values(spec.format, raw.data(), OIIO::TypeDesc::FLOAT, img->pixels,
                                                 static_cast<int>(spec.image_pixels() * static_cast<size_t>(nc)));
        // A reader may return true and only leave its error behind: libtiff's "Read error at
        // scanline" for a strip past the end of the file read as zeros (issue 31)
        std::string late = read_ok ? in->geterror() : std::string();
        if (!late.empty()) {
            host->image_destroy(img);
            return fail(err, GR_E_INPUT, path, "reading pixels (truncated or damaged file)", late);
        }
        if (!read_ok) {
            std::string why = in->geterror();
            const std::string lib = cap.take();
            add_lib_text(why, lib);
            gr_status st = fail(err, GR_E_INPUT, path, "reading pixels", why);
            host->image_destroy(img);
            return st;
        }
        in->close();
        // Integer files hold display-encoded codes; decode to linear only on request, and
        // never alpha (stored linear) or files that declare themselves linear.
        const bool integer = spec.format.basetype == OIIO::TypeDesc::UINT8 || spec.format.basetype == OIIO::TypeDesc::UINT16;
        const std::string cs = spec.get_string_attribute("oiio:ColorSpace");
        const bool decode = linearize && integer && !OIIO::Strutil::iequals(cs, "Linear");
        if (info) {
            info->bits = static_cast<int>(spec.format.size() * 8);
            info->integer = integer;
            info->decoded = decode;
            std::snprintf(info->colorspace, sizeof info->colorspace, "%s", cs.c_str());
            if (integer) info->n_top_code = count_top_code(img, spec.alpha_channel);
        }
        if (decode) {
            const size_t n = static_cast<size_t>(img->width) * static_cast<size_t>(img->height);
            for (size_t p = 0; p < n; p++)
                for (int c = 0; c < nc; c++)
                    if (c != spec.alpha_channel)
                        img->pixels[p * static_cast<size_t>(nc) + static_cast<size_t>(c)] =
                            srgb_decode(img->pixels[p * static_cast<size_t>(nc) + static_cast<size_t>(c)]);
        }
        gr_status st = host->image_check_finite(img, path, err);
        if (st != GR_OK) {
            host->image_destroy(img);
            if (err) err->status = GR_E_INPUT; // a non-finite sample in a file is bad input
            return GR_E_INPUT;
        }
        *out = img;
        return GR_OK;
    } catch (...) {
        host->image_destroy(img);
        return exception_status(err, path, "reading image");
    }
}

static gr_status oiio_write(const char *path, const gr_image *img, gr_error *err)
{
    if (!path || !path[0]) return host->fail(err, GR_E_USAGE, "image write: no output path");
    if (!image_ok(img)) return host->fail(err, GR_E_INPUT, "%s: no image or bad image size", path);
    gr_status st = host->image_check_finite(img, path, err);
    if (st != GR_OK) return st;
    try {
        OIIO::ImageSpec spec(img->width, img->height, img->nchannels, OIIO::TypeDesc::FLOAT);
        spec.alpha_channel = -1;
        for (int c = 0; c < img->nchannels; c++) {
            spec.channelnames[static_cast<size_t>(c)] = img->names[c];
            if (std::strcmp(img->names[c], "A") == 0) spec.alpha_channel = c;
        }
        return write_via_temp(path, spec, OIIO::TypeDesc::FLOAT, img->pixels, err);
    } catch (...) {
        return exception_status(err, path, "writing image");
    }
}

// ---- color maps and text for the comparison's difference images (compare module) ----------
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

static gr_status oiio_color_map(const gr_image *src, int channel, const char *map, gr_image **out,
                                       gr_error *err)
{
    if (out) *out = nullptr;
    if (!out || !image_ok(src)) return host->fail(err, GR_E_INPUT, "color map: no image or bad image size");
    if (channel < 0 || channel >= src->nchannels)
        return host->fail(err, GR_E_INPUT, "color map: channel %d, the image has %d", channel, src->nchannels);
    if (!map || !map[0]) return host->fail(err, GR_E_INPUT, "color map: no map name");
    gr_image *res = nullptr;
    try {
        const size_t n = static_cast<size_t>(src->width) * static_cast<size_t>(src->height);
        OIIO::ImageBuf in(OIIO::ImageSpec(src->width, src->height, 1, OIIO::TypeDesc::FLOAT));
        float *v = static_cast<float *>(in.localpixels());
        for (size_t p = 0; p < n; p++) {
            float x = src->pixels[p * static_cast<size_t>(src->nchannels) + static_cast<size_t>(channel)];
            v[p] = std::isfinite(x) ? (x < 0.0f ? 0.0f : (x > 1.0f ? 1.0f : x)) : 0.0f;
        }
        OIIO::ImageBuf mapped = OIIO::ImageBufAlgo::color_map(in, 0, map);
        if (mapped.has_error() || mapped.nchannels() != 3)
            return host->fail(err, GR_E_INPUT, "color map '%s': %s", map, one_line(mapped.geterror()).c_str());
        res = host->image_create(src->width, src->height, 3, nullptr);
        if (!res) return host->fail(err, GR_E_NOMEM, "color map: cannot allocate %d x %d", src->width, src->height);
        if (!mapped.get_pixels(OIIO::ROI(0, src->width, 0, src->height, 0, 1, 0, 3), OIIO::TypeDesc::FLOAT,
                               res->pixels)) {
            host->image_destroy(res);
            return host->fail(err, GR_E_RUNTIME, "color map '%s': %s", map, one_line(mapped.geterror()).c_str());
        }
        *out = res;
        return GR_OK;
    } catch (...) {
        host->image_destroy(res);
        return exception_status(err, map, "color map");
    }
}

static gr_status oiio_render_text(gr_image *img, int x, int y, const char *text, int size_px,
                                         const float rgb[3], int align, gr_error *err)
{
    if (!image_ok(img) || !text || !rgb || size_px <= 0)
        return host->fail(err, GR_E_INPUT, "text: bad image, text, color or size");
    try {
        OIIO::ImageSpec spec(img->width, img->height, img->nchannels, OIIO::TypeDesc::FLOAT);
        OIIO::ImageBuf buf(spec, img->pixels); // wraps img's pixels: drawn in place
        std::vector<float> color(static_cast<size_t>(img->nchannels), 1.0f);
        for (int c = 0; c < 3 && c < img->nchannels; c++) color[static_cast<size_t>(c)] = rgb[c];
        const OIIO::ImageBufAlgo::TextAlignX ax = align == 1 ? OIIO::ImageBufAlgo::TextAlignX::Center
                                               : (align == 2 ? OIIO::ImageBufAlgo::TextAlignX::Right : OIIO::ImageBufAlgo::TextAlignX::Left);
        OIIO::ROI roi = OIIO::get_roi(spec);
        roi.chend = img->nchannels < 3 ? img->nchannels : 3;
        for (const char *font : {"DejaVuSans", ""}) {
            if (OIIO::ImageBufAlgo::render_text(buf, x, y, text, size_px, font, color, ax,
                                                OIIO::ImageBufAlgo::TextAlignY::Baseline, 0, roi))
                return GR_OK;
            (void)buf.geterror(); // clear, then try the next font
        }
        return host->fail(err, GR_E_RUNTIME, "text '%s': no usable font (DejaVuSans or OpenImageIO's default)", text);
    } catch (...) {
        return exception_status(err, text, "drawing text");
    }
}

// ---- animations for the sequence report (report module) ------------------------------------

static gr_status oiio_write_animation(const char *path, const gr_image *const *frames, int n, double fps,
                                             gr_error *err)
{
    if (!path || !path[0]) return host->fail(err, GR_E_USAGE, "animation write: no output path");
    if (!frames || n < 1 || !(fps > 0) || !std::isfinite(fps))
        return host->fail(err, GR_E_INPUT, "%s: no frames or a bad frame rate", path);
    for (int i = 0; i < n; i++)
        if (!image_ok(frames[i]) || frames[i]->nchannels < 3 || frames[i]->width != frames[0]->width ||
            frames[i]->height != frames[0]->height)
            return host->fail(err, GR_E_INPUT, "%s: frame %d: missing, not RGB, or another size than frame 0", path, i);
    try {
        auto out = OIIO::ImageOutput::create(path);
        if (!out) return fail(err, GR_E_INPUT, path, "no writer for this file type", OIIO::geterror());
        if (!out->supports("multiimage") || !out->supports("appendsubimage"))
            return host->fail(err, GR_E_INPUT, "%s: this format holds no animation", path);
        const int w = frames[0]->width, h = frames[0]->height;
        OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::UINT8);
        // frames per second as a rational of whole hundredths (the GIF delay unit)
        int delay = static_cast<int>(std::lround(100.0 / fps));
        if (delay < 1) delay = 1;
        const int rate[2] = {100, delay};
        spec.attribute("FramesPerSecond", OIIO::TypeRational, rate);
        spec.attribute("oiio:Movie", 1);
        spec.attribute("oiio:LoopCount", 0);
        spec.attribute("gif:LoopCount", 0);
        std::vector<OIIO::ImageSpec> specs(static_cast<size_t>(n), spec);
        gr_outfile of;
        gr_status st = host->outfile_begin(&of, path, err);
        if (st != GR_OK) return st;
        const std::string tmp = of.tmp;
        const std::string format = out->format_name();
        std::vector<unsigned char> codes(static_cast<size_t>(w) * static_cast<size_t>(h) * 3);
        if (!out->open(tmp, n, specs.data())) {
            st = fail(err, GR_E_IO, path, "cannot create file", out->geterror());
        } else {
            for (int i = 0; i < n && st == GR_OK; i++) {
                if (i > 0 && !out->open(tmp, specs[static_cast<size_t>(i)], OIIO::ImageOutput::AppendSubimage)) {
                    st = fail(err, GR_E_IO, path, "appending a frame", out->geterror());
                    break;
                }
                const gr_image *f = frames[i];
                for (size_t p = 0; p < codes.size() / 3; p++)
                    for (size_t c = 0; c < 3; c++) {
                        const float x = f->pixels[p * static_cast<size_t>(f->nchannels) + c];
                        const float v = std::isfinite(x) ? (x < 0.0f ? 0.0f : (x > 1.0f ? 1.0f : x)) : 0.0f;
                        codes[p * 3 + c] = static_cast<unsigned char>(std::lround(v * 255.0f));
                    }
                if (!out->write_image(OIIO::TypeDesc::UINT8, codes.data()))
                    st = fail(err, GR_E_IO, path, "writing a frame", out->geterror());
            }
            if (!out->close() && st == GR_OK) st = fail(err, GR_E_IO, path, "closing file", out->geterror());
        }
        out.reset();
        if (st == GR_OK) { // read back: every frame must be there
            StderrCapture quiet;
            auto in = OIIO::ImageInput::create(format);
            OIIO::ImageSpec got;
            int count = 0;
            if (in && in->open(tmp, got)) {
                do {
                    count++;
                } while (in->seek_subimage(count, 0));
                in->close();
            }
            if (in) (void)in->geterror();
            (void)OIIO::geterror();
            if (count != n)
                st = host->fail(err, GR_E_IO, "%s: cannot write: %d of %d frames read back (is the disk full?)", path,
                             count, n);
        }
        if (st == GR_OK) return host->outfile_commit(&of, 1, err);
        host->outfile_abort(&of);
        return st;
    } catch (...) {
        return exception_status(err, path, "writing animation");
    }
}

// ---- the module's entry (oiio_module.h) -----------------------------------------------------

extern "C" __attribute__((visibility("default"))) const gr_oiio_api *gr_oiio_module_open(const gr_oiio_host *h, int abi)
{
    static const gr_oiio_api api = {oiio_version,   oiio_read_info,   oiio_write,
                                    oiio_color_map, oiio_render_text, oiio_write_animation};
    if (abi != GR_OIIO_MODULE_ABI || !h) return nullptr;
    host = h;
    return &api;
}
