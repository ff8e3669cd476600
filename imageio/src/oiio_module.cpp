// The table of the OpenImageIO module: its only exported symbol.
#include "oiio_module_pvt.h"

extern "C" __attribute__((visibility("default"))) const conus::imageio::OiioFunctions* conusImageioOiio() {
    using namespace conus::imageio;
    static const OiioFunctions functions{&oiio::readImageFile, &oiio::writeImageFile, &oiio::checkImageOutput,
                                         &oiio::sampleTypesOf, &oiio::linearize,      &oiio::displayEncoded,
                                         &oiio::repairNonFinite,
                                         &oiio::drawText,      &oiio::renderTextPanel, &oiio::textWidth,
                                         &oiio::wrapText};
    return &functions;
}
