// Face detection for the `faces` importance rule (importance.h): OpenCV's Haar cascade (Debian's
// opencv-data). The only file that includes OpenCV; its exceptions become conus::Error here. Built
// as the module libconus_faces (codec/CMakeLists.txt), loaded only when faces are asked for:
// OpenCV's detectors and their dnn stack stay out of every other process.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <vector>

#include <opencv2/imgproc.hpp>
#include <opencv2/objdetect.hpp>

#include "conus/core/error.h"
#include "conus/codec/builders/importance.h"

namespace conus::codec {
namespace {

// Where Debian's opencv-data puts the frontal-face cascade.
constexpr const char* kCascadePaths[] = {
    "/usr/share/opencv4/haarcascades/haarcascade_frontalface_default.xml",
    "/usr/share/opencv/haarcascades/haarcascade_frontalface_default.xml",
};

// `image` is display-encoded (the cascade was trained on ordinary 8-bit photographs).
Image detectFaceImportance(const Image& image) {
    if (image.empty()) throw Error(ErrorCode::InvalidArgument, "no image to find faces in");
    // Detection on an 8-bit grey copy at most 1024 px a side: the cascade works on 24 px windows,
    // and larger pictures only cost time.
    const double scale = std::min(1.0, 1024.0 / std::max(image.width, image.height));
    const int w = std::max(1, static_cast<int>(image.width * scale)), h = std::max(1, static_cast<int>(image.height * scale));
    const int r = image.channelIndex("R"), g = image.channelIndex("G"), b = image.channelIndex("B");
    cv::Mat full(image.height, image.width, CV_32F);
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
            full.at<float>(y, x) = (r >= 0 && g >= 0 && b >= 0)
                                       ? 0.299f * image.at(x, y, r) + 0.587f * image.at(x, y, g) + 0.114f * image.at(x, y, b)
                                       : image.at(x, y, 0);
    std::vector<cv::Rect> faces;
    try {
        cv::Mat small, grey;
        cv::resize(full, small, cv::Size(w, h), 0, 0, cv::INTER_AREA);
        small.convertTo(grey, CV_8U, 255.0);
        cv::equalizeHist(grey, grey);
        cv::CascadeClassifier cascade;
        bool loaded = false;
        for (const char* path : kCascadePaths)
            if (std::filesystem::exists(path) && (loaded = cascade.load(path))) break;
        if (!loaded)
            throw Error(ErrorCode::Unsupported,
                        "the face detector's data is missing (install Debian's opencv-data)");
        cascade.detectMultiScale(grey, faces, 1.1, 5, 0, cv::Size(24, 24));
    } catch (const cv::Exception& e) {
        throw Error(ErrorCode::Unsupported, std::string("face detection failed: ") + e.what());
    }
    if (faces.empty())
        throw Error(ErrorCode::Unsupported, "no face found in the image; give --focus or an importance image");

    // A soft disc over each face (a little larger than the detection box, which crops the hair).
    Image importance = makeImage(w, h, {"Y"});
    for (const auto& f : faces) {
        const double cx = f.x + 0.5 * f.width, cy = f.y + 0.45 * f.height, radius = 0.75 * std::max(f.width, f.height);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const double d = std::hypot(x + 0.5 - cx, y + 0.5 - cy) / radius;
                const double v = d < 1 ? 1.0 : d < 1.5 ? 0.5 + 0.5 * std::cos((d - 1) * 2 * 3.14159265358979) : 0.0;
                importance.at(x, y) = std::max(importance.at(x, y), static_cast<float>(v));
            }
    }
    return importance;
}

}  // namespace
}  // namespace conus::codec

// The module's one exported symbol (importance.cpp loads it).
extern "C" __attribute__((visibility("default"))) conus::codec::FaceImportanceFunction conusFaceImportance() {
    return &conus::codec::detectFaceImportance;
}
