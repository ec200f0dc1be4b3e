// libxml2, loaded with dlopen on the first X3D XML read instead of linked: linked, it and the ICU
// libraries it pulls in slow every start of vrmlray, XML or not, while most scenes are classic
// VRML (bench/README.md, "Figures behind the comments").
// Only the headers are needed at build time.
#pragma once
#include <libxml/parser.h>

#include <string>

namespace vr {

// The libxml2 functions the X3D XML reader calls, by their own types.
struct LibXml {
    decltype(&::xmlInitParser) InitParser = nullptr;
    decltype(&::xmlSetExternalEntityLoader) SetExternalEntityLoader = nullptr;
    decltype(&::xmlSetGenericErrorFunc) SetGenericErrorFunc = nullptr;
    decltype(&::xmlCreatePushParserCtxt) CreatePushParserCtxt = nullptr;
    decltype(&::xmlCtxtUseOptions) CtxtUseOptions = nullptr;
    decltype(&::xmlParseChunk) ParseChunk = nullptr;
    decltype(&::xmlFreeDoc) FreeDoc = nullptr;
    decltype(&::xmlFreeParserCtxt) FreeParserCtxt = nullptr;
    decltype(&::xmlDictOwns) DictOwns = nullptr;
    decltype(&::xmlStopParser) StopParser = nullptr;
};

// The library, loaded (and initialised, with external entities refused) on the first call; null
// with `error` set ("libxml2.so.2 could not be loaded: WHY") when it cannot be. Thread-safe.
const LibXml* libxml(std::string& error);

}  // namespace vr
