// JPEGs against the screen the readers run before OpenImageIO opens one (imageio's image_read.cpp):
// progressive files of endless scans, and Photoshop (APP13) segments whose image resources or
// IPTC records say more bytes than they hold. Each goes through the real `conus` and is read, or
// refused in one line with exit 1 within a bounded peak memory.
#include <OpenImageIO/imageio.h>

#include "hostile_fixture.h"

namespace {

using namespace conus::hostile;

class JpegHostile : public Hostile {
protected:
    // Writes `name`, a w x h RGB JPEG (progressive when asked) whose bytes ramp as (i * step) % modulus.
    void writeJpeg(const std::string& name, int w, int h, std::size_t step, std::size_t modulus, bool progressive) {
        OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::UINT8);
        if (progressive) spec.attribute("jpeg:progressive", 1);
        std::vector<unsigned char> pixels(std::size_t(w) * h * 3);
        for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<unsigned char>((i * step) % modulus);
        auto out = OIIO::ImageOutput::create(path(name));
        ASSERT_TRUE(out && out->open(path(name), spec));
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, pixels.data()));
        out->close();
    }
};

TEST_F(JpegHostile, AJpegOfEndlessScansIsRefusedBeforeDecoding) {
    ASSERT_NO_FATAL_FAILURE(writeJpeg("plain.jpg", 64, 48, 37, 251, true));
    const std::string jpeg = slurp(path("plain.jpg"));
    int scans = 0;
    for (std::size_t at = 0; (at = jpeg.find("\xFF\xDA", at)) != std::string::npos; ++at) ++scans;
    ASSERT_GT(scans, 1) << "libjpeg's progression has several scans";
    ASSERT_LE(scans, conus::kMaxJpegScans);
    Outcome r = run({"uniform", path("plain.jpg"), "-o", path("plain.exr")});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    // The last scan (a refinement) repeated: libjpeg decodes every repeat again.
    const std::size_t sos = jpeg.rfind("\xFF\xDA"), eoi = jpeg.rfind("\xFF\xD9");
    ASSERT_LT(sos, eoi);
    const std::string scan = jpeg.substr(sos, eoi - sos);
    const auto repeated = [&](int times) {
        std::string file = jpeg.substr(0, eoi);
        for (int i = 0; i < times; ++i) file += scan;
        return file + "\xFF\xD9";
    };
    write("few.jpg", repeated(3));
    r = run({"uniform", path("few.jpg"), "-o", path("few.exr")});
    EXPECT_EQ(r.exitCode, 0) << r.err;  // within the limit it reads
    write("many.jpg", repeated(conus::kMaxJpegScans));
    r = run({"uniform", path("many.jpg"), "-o", path("x.exr")});
    expectRefused(r, "uniform", "a JPEG of more than " + std::to_string(conus::kMaxJpegScans) + " scans");
    expectMemory(r, 300);
    r = runTool("conus", {"uniform", "-", "-o", path("x.exr")}, path("many.jpg"));
    expectRefused(r, "uniform", "standard input: a JPEG of more than");
    r = run({"heightfield", "encode", path("many.jpg"), "-o", path("t.exr"), "--size", "16x16"});
    expectRefused(r, "heightfield", "a JPEG of more than");
    EXPECT_FALSE(fs::exists(path("x.exr")) || fs::exists(path("t.exr")));
    const std::string shared = hostileData("round4/images/scans_2000.jpg");
    CONUS_REQUIRE(shared);
    r = run({"uniform", shared, "-o", path("x.exr")});
    expectRefused(r, "uniform", "a JPEG of more than");
    expectMemory(r, 300);
}

// A JPEG with a Photoshop (APP13) segment after its SOI: one IPTC caption record whose length field
// says `recordLength` and whose resource says `resourceSize` (the record holds 9 bytes, the resource 14).
std::string withIptc(const std::string& jpeg, int recordLength, std::uint32_t resourceSize) {
    const std::string caption = "A caption";
    std::string records = "\x1C\x02\x78";
    records += static_cast<char>(recordLength >> 8);
    records += static_cast<char>(recordLength & 0xFF);
    records += caption;
    std::string body = std::string("Photoshop 3.0", 14) + "8BIM" + std::string("\x04\x04\x00\x00", 4);
    for (int shift = 24; shift >= 0; shift -= 8) body += static_cast<char>((resourceSize >> shift) & 0xFF);
    body += records;
    const std::size_t length = body.size() + 2;
    std::string segment = "\xFF\xED";
    segment += static_cast<char>(length >> 8);
    segment += static_cast<char>(length & 0xFF);
    return jpeg.substr(0, 2) + segment + body + jpeg.substr(2);
}

TEST_F(JpegHostile, AJpegWhoseIptcRecordsRunPastTheirSegmentIsRefused) {
    ASSERT_NO_FATAL_FAILURE(writeJpeg("base.jpg", 40, 24, 53, 241, false));
    const std::string jpeg = slurp(path("base.jpg"));
    write("fine.jpg", withIptc(jpeg, 9, 14));
    Outcome r = run({"uniform", path("fine.jpg"), "-o", path("fine.exr")});
    EXPECT_EQ(r.exitCode, 0) << r.err;  // a well-formed record reads
    EXPECT_TRUE(fs::exists(path("fine.exr")));
    const struct {
        const char* name;
        int recordLength;
        std::uint32_t resourceSize;
        const char* said;
    } cases[] = {
        {"record.jpg", 0x40, 14, "an IPTC record runs past the segment"},
        {"resource.jpg", 9, 0x47, "its IPTC block says more bytes than the segment holds"},
        {"extended.jpg", 0x8004, 14, "an IPTC record runs past the segment"},
    };
    for (const auto& c : cases) {
        SCOPED_TRACE(c.name);
        write(c.name, withIptc(jpeg, c.recordLength, c.resourceSize));
        r = run({"uniform", path(c.name), "-o", path("x.exr")});
        expectRefused(r, "uniform", c.said);
        r = runTool("conus", {"uniform", "-", "-o", path("x.exr")}, path(c.name));
        expectRefused(r, "uniform", "standard input: a JPEG whose Photoshop (APP13) segment is damaged");
    }
    // A named first resource: OpenImageIO takes its IPTC size from fixed offsets, here two bytes of
    // the name (0xFFFF), whatever the resource's own size says: screened as OpenImageIO reads it.
    std::string named = std::string("Photoshop 3.0", 14) + "8BIM" + std::string("\x04\x04\x06" "AAA\xFF\xFF" "A\x00", 10) +
                        std::string("\x00\x00\x00\x09\x1C\x02\x78\x00\x04" "abcd", 13);
    std::string segment = "\xFF\xED";
    segment += static_cast<char>((named.size() + 2) >> 8);
    segment += static_cast<char>((named.size() + 2) & 0xFF);
    write("named.jpg", jpeg.substr(0, 2) + segment + named + jpeg.substr(2));
    r = run({"uniform", path("named.jpg"), "-o", path("x.exr")});
    expectRefused(r, "uniform", "its IPTC block says more bytes than the segment holds");
    // Resources OpenImageIO does not read (the first not IPTC) are not screened: a thumbnail
    // resource (0x0409) whose size runs on into a next segment, as large resources do, reads.
    std::string thumb = std::string("Photoshop 3.0", 14) + "8BIM" + std::string("\x04\x09\x00\x00\x00\x01\x00\x00", 8) + "data";
    segment = "\xFF\xED";
    segment += static_cast<char>((thumb.size() + 2) >> 8);
    segment += static_cast<char>((thumb.size() + 2) & 0xFF);
    write("thumb.jpg", jpeg.substr(0, 2) + segment + thumb + jpeg.substr(2));
    r = run({"uniform", path("thumb.jpg"), "-o", path("thumb.exr")});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_FALSE(fs::exists(path("x.exr")));
}

}  // namespace
