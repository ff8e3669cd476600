#include "arguments.h"

#include <pybind11/numpy.h>

#include <algorithm>
#include <sstream>

#include "conus/core/error.h"
#include "conus/core/limits.h"
#include "conus/imageio/image_file.h"

namespace conus::python {
namespace {

std::string shortened(std::string text) {
    if (text.size() > 40) text = text.substr(0, 37) + "...";
    return text;
}

bool isText(py::handle value) { return py::isinstance<py::str>(value) || py::isinstance<py::bytes>(value); }

// A sequence that is not text (lists, tuples, arrays).
bool isSequence(py::handle value) { return !isText(value) && PySequence_Check(value.ptr()); }

bool isNumber(py::handle value) { return !isText(value) && PyNumber_Check(value.ptr()) && !isSequence(value); }

bool isWhole(py::handle value) { return !py::isinstance<py::bool_>(value) && PyIndex_Check(value.ptr()); }

[[noreturn]] void invalid(const std::string& text) { throw Error(ErrorCode::InvalidArgument, text); }

}  // namespace

std::string quotedChoices(const std::vector<std::string>& names) {
    std::string list;
    for (std::size_t i = 0; i < names.size(); ++i)
        list.append(i == 0 ? "" : i + 1 == names.size() ? " or " : ", ").append("'").append(names[i]).append("'");
    return list;
}

namespace {

std::string shape(const py::array& a) {
    std::ostringstream text;
    text << '(';
    for (py::ssize_t d = 0; d < a.ndim(); ++d) text << (d ? ", " : "") << a.shape(d);
    text << (a.ndim() == 1 ? ",)" : ")");
    return text.str();
}

// The value as a numpy array, or a TypeError that says what was given instead.
py::array asArray(py::handle value, const char* what, const char* hint) {
    const bool path = isText(value) || py::hasattr(value, "__fspath__");
    if (path || value.is_none())
        throw py::type_error(std::string(what) + " must be a numpy array (height, width) or (height, width, channels), not " +
                             describe(value) + (path ? hint : ""));
    py::array array;
    try {
        array = py::module_::import("numpy").attr("asarray")(value);
    } catch (const py::error_already_set&) {
        throw py::type_error(std::string(what) + " must be an array of numbers, not " + describe(value));
    }
    const char kind = array.dtype().kind();
    if (kind != 'f' && kind != 'u' && kind != 'i' && kind != 'b')
        throw py::type_error(std::string(what) + " must be an array of numbers, not " + describe(value));
    return array;
}

Image toImage(const py::array& array, std::optional<std::vector<std::string>> channels, const char* what, float scale) {
    if (array.ndim() != 2 && array.ndim() != 3)
        invalid(std::string(what) + " must have shape (height, width) or (height, width, channels), not " + shape(array));
    const py::ssize_t h = array.shape(0), w = array.shape(1), c = array.ndim() == 3 ? array.shape(2) : 1;
    if (h == 0 || w == 0) invalid(std::string(what) + " of shape " + shape(array) + " hold no pixels");
    if (c == 0)
        invalid(std::string(what) + " of shape " + shape(array) + " have no channels: give (height, width) or (height, width, channels)");
    // (3, H, W), as torch and some readers hold a picture, would be 3 rows of W channels: refused
    // unless the channel names say that many channels are meant.
    if (array.ndim() == 3 && h <= 4 && c > 4 && !(channels && py::ssize_t(channels->size()) == c))
        invalid(std::string(what) + " of shape " + shape(array) + " look channel-first (channels, height, width); CoNUS takes " +
                "(height, width, channels): pass numpy.moveaxis(" + what + ", 0, -1)");
    std::vector<std::string> names = channels ? *channels : defaultChannelNames(int(c));
    if (py::ssize_t(names.size()) != c)
        invalid(std::string(what) + " has " + std::to_string(c) + " channels but " + std::to_string(names.size()) +
                " names were given");
    if (h > kMaxImageSide || w > kMaxImageSide)
        throw Error(ErrorCode::LimitExceeded, std::string(what) + " of " + std::to_string(w) + "x" + std::to_string(h) +
                                                  " pixels is beyond the limit of " + std::to_string(kMaxImageSide) + " a side");
    using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;
    const FloatArray values = FloatArray::ensure(array);
    Image image = makeImage(int(w), int(h), std::move(names));
    std::transform(values.data(), values.data() + image.pixels.size(), image.pixels.begin(),
                   [scale](float v) { return v * scale; });
    return image;
}

// 1/255 for uint8, 1/65535 for uint16 (as an 8- or 16-bit file's codes read); 0 for other integers.
float codeScale(const py::array& array) {
    if (array.dtype().kind() != 'u') return 0.0f;
    if (array.itemsize() == 1) return 1.0f / 255.0f;
    if (array.itemsize() == 2) return 1.0f / 65535.0f;
    return 0.0f;
}

}  // namespace

std::vector<std::string> defaultChannelNames(int count) {
    switch (count) {
        case 1: return {"Y"};
        case 2: return {"Y", "A"};
        case 3: return {"R", "G", "B"};
        case 4: return {"R", "G", "B", "A"};
        default: {
            std::vector<std::string> names;
            for (int c = 0; c < count; ++c) names.push_back("C" + std::to_string(c));
            return names;
        }
    }
}

std::string describe(py::handle value) {
    if (value.is_none()) return "None";
    if (py::isinstance<py::bool_>(value)) return value.cast<bool>() ? "True" : "False";
    if (py::isinstance<py::str>(value)) return "the str '" + shortened(value.cast<std::string>()) + "'";
    if (py::isinstance<py::array>(value)) {
        const py::array a = py::reinterpret_borrow<py::array>(value);
        return "an array of shape " + shape(a) + " and dtype " + py::str(a.dtype()).cast<std::string>();
    }
    const std::string type = py::str(value.get_type().attr("__name__")).cast<std::string>();
    if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value))
        return shortened(py::repr(value).cast<std::string>()) + " (a " + type + ")";
    return "a " + type + " " + shortened(py::repr(value).cast<std::string>());
}

Image pixelsFrom(py::handle pixels, const std::optional<std::vector<std::string>>& channels, const char* what,
                 const PixelRules& rules) {
    const std::vector<std::string> colorspaces{kAutoColorspace, enumName(Transfer::Srgb), enumName(Transfer::Linear)};
    if (std::find(colorspaces.begin(), colorspaces.end(), rules.colorspace) == colorspaces.end())
        invalid("colorspace must be " + quotedChoices(colorspaces) + ", not '" + rules.colorspace + "'");
    const imageio::NonFiniteRepair repair = enumArgument<imageio::NonFiniteRepair>(rules.fixNonFinite, "fix_nonfinite");
    const bool autoColorspace = rules.colorspace == kAutoColorspace;
    const py::array array = asArray(pixels, what, "; read a picture file with conus.read_image");
    const float scale = codeScale(array);
    const bool codes = scale > 0.0f;
    if (array.dtype().kind() != 'f' && !codes)
        throw py::type_error(std::string(what) + " of dtype " + py::str(array.dtype()).cast<std::string>() +
                             ": give float linear light, or uint8 / uint16 display-encoded codes (as an 8- or 16-bit PNG "
                             "holds)");
    Image image = toImage(array, channels, what, codes ? scale : 1.0f);
    if (rules.colorspace == enumName(Transfer::Srgb) || (codes && autoColorspace)) imageio::linearize(image);
    if (codes) return image;
    if (const std::int64_t bad = imageio::countNonFinite(image); bad > 0) {
        const std::string count = std::to_string(bad) + (bad == 1 ? " NaN or infinite value" : " NaN or infinite values");
        if (repair == imageio::NonFiniteRepair::Keep) {
            warn(std::string(what) + ", " + describe(pixels) + ", hold " + count +
                 "; filtering spreads them to their neighbours (repair with fix_nonfinite=" +
                 quotedChoices(enumNames({imageio::NonFiniteRepair::Box3, imageio::NonFiniteRepair::Black})) + ")");
        } else {
            imageio::repairNonFinite(image, repair);
        }
    }
    return image;
}

Image dataFrom(py::handle values, const char* what) {
    const py::array array = asArray(values, what, "; read an importance picture with conus.read_image");
    const char kind = array.dtype().kind();
    const float scale = codeScale(array);
    if (kind != 'f' && kind != 'b' && scale == 0.0f)
        throw py::type_error(std::string(what) + " of dtype " + py::str(array.dtype()).cast<std::string>() +
                             ": give float values, or uint8 / uint16 codes (as an 8- or 16-bit PNG holds)");
    return toImage(array, std::nullopt, what, scale > 0.0f ? scale : 1.0f);
}

std::vector<codec::Focus> fociFrom(py::handle foci) {
    if (foci.is_none()) return {};
    if (!isSequence(foci))
        throw py::type_error("foci must be a list of (u, v, r, k), such as [(0.42, 0.31, 0.08, 4)], not " + describe(foci));
    const py::sequence list = py::reinterpret_borrow<py::sequence>(foci);
    // Numbers alone are one focus (of the wrong length, it is said so below).
    const bool one = list.size() > 0 && std::all_of(list.begin(), list.end(), [](py::handle v) { return isNumber(v); });
    std::vector<codec::Focus> out;
    for (std::size_t i = 0; i < (one ? 1 : list.size()); ++i) {
        const py::handle item = one ? foci : list[i];
        const std::string name = "focus " + std::to_string(i + 1) + " " + shortened(py::repr(item).cast<std::string>());
        if (!isSequence(item)) throw py::type_error(name + " is not (u, v, r, k), such as (0.42, 0.31, 0.08, 4)");
        const py::sequence values = py::reinterpret_borrow<py::sequence>(item);
        if (values.size() != 4)
            invalid(name + " has " + std::to_string(values.size()) + " values; a focus is (u, v, r, k), such as (0.42, 0.31, 0.08, 4)");
        double v[4];
        for (std::size_t c = 0; c < 4; ++c) {
            if (!isNumber(values[c])) throw py::type_error(name + ": " + describe(values[c]) + " is not a number");
            v[c] = values[c].cast<double>();
        }
        const codec::Focus focus{v[0], v[1], v[2], v[3]};
        try {
            codec::checkFocus(focus);
        } catch (const Error& e) {
            invalid(name + ": " + e.what());
        }
        out.push_back(focus);
    }
    return out;
}

std::optional<std::vector<std::string>> channelsFrom(py::handle channels) {
    if (channels.is_none()) return std::nullopt;
    if (py::isinstance<py::str>(channels))
        throw py::type_error("channels must be a list of names such as ['R', 'G', 'B'], not " + describe(channels));
    if (!isSequence(channels)) throw py::type_error("channels must be a list of names such as ['R', 'G', 'B'], not " + describe(channels));
    std::vector<std::string> names;
    for (py::handle name : py::reinterpret_borrow<py::sequence>(channels)) {
        if (!py::isinstance<py::str>(name)) throw py::type_error("channels: " + describe(name) + " is not a channel name (a str)");
        names.push_back(name.cast<std::string>());
    }
    return names;
}

std::optional<std::pair<int, int>> sizeFrom(py::handle size, const char* what) {
    if (size.is_none()) return std::nullopt;
    const std::string expected = std::string(what) + " must be (width, height) in whole pixels, such as (512, 384), not ";
    if (!isSequence(size)) throw py::type_error(expected + describe(size));
    const py::sequence pair = py::reinterpret_borrow<py::sequence>(size);
    if (pair.size() != 2 || !isWhole(pair[0]) || !isWhole(pair[1])) throw py::type_error(expected + describe(size));
    const long long w = pair[0].cast<long long>(), h = pair[1].cast<long long>();
    if (w < 1 || h < 1 || w > kMaxImageSide || h > kMaxImageSide)
        invalid(std::string(what) + " " + py::repr(size).cast<std::string>() + ": each side must be a whole number in [1, " +
                std::to_string(kMaxImageSide) + "]");
    return std::pair<int, int>{int(w), int(h)};
}

codec::View viewFrom(py::handle view) {
    const std::string expected = "view must be (u0, v0, u1, v1), such as (0.2, 0.2, 0.4, 0.4), not ";
    if (!isSequence(view)) throw py::type_error(expected + describe(view));
    const py::sequence values = py::reinterpret_borrow<py::sequence>(view);
    if (values.size() != 4 || !std::all_of(values.begin(), values.end(), [](py::handle v) { return isNumber(v); }))
        throw py::type_error(expected + describe(view));
    const codec::View out{values[0].cast<double>(), values[1].cast<double>(), values[2].cast<double>(), values[3].cast<double>()};
    codec::checkView(out, py::repr(view).cast<std::string>());
    return out;
}

int iterationsFrom(py::handle fit) {
    if (!isWhole(fit))
        throw py::type_error("fit is a number of least-squares iterations (fit=4 as `conus encode --fit`), not " + describe(fit));
    const long long n = fit.cast<long long>();
    if (n < 0 || n > 100) invalid("fit must be 0 (none) or 1 to 100 iterations (as --fit-iterations), not " + std::to_string(n));
    return int(n);
}

void requireReal(const py::array& input, const std::string& what) {
    const char kind = input.dtype().kind();
    if (kind != 'f' && kind != 'i' && kind != 'u' && kind != 'b')
        throw Error(ErrorCode::InvalidArgument, what + " must be an array of real numbers, not of dtype " +
                                                    py::str(input.dtype()).cast<std::string>());
}

py::array toArray(Image image) {
    auto* held = new Image(std::move(image));
    py::capsule owner(held, [](void* p) { delete static_cast<Image*>(p); });
    const py::ssize_t c = held->channelCount();
    return py::array_t<float>({py::ssize_t(held->height), py::ssize_t(held->width), c},
                              {py::ssize_t(held->width) * c * 4, c * 4, py::ssize_t(4)}, held->pixels.data(), owner);
}

void warn(const std::string& text) { py::module_::import("conus").attr("_warn")(text); }

}  // namespace conus::python
