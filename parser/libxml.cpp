#include "parser/libxml.h"

#include <dlfcn.h>

namespace vr {
namespace {

xmlParserInputPtr refuse_external_entity(const char*, const char*, xmlParserCtxtPtr) {
    return nullptr;
}

struct Loaded {
    LibXml api;
    std::string error;  // empty: loaded
};

Loaded load() {
    Loaded out;
    void* library = dlopen("libxml2.so.2", RTLD_NOW | RTLD_LOCAL);
    if (!library) {
        const char* why = dlerror();
        out.error =
            std::string("libxml2.so.2 could not be loaded: ") + (why ? why : "unknown reason");
        return out;
    }
    LibXml& x = out.api;
    auto get = [&](auto& function, const char* name) {
        function =
            reinterpret_cast<std::remove_reference_t<decltype(function)>>(dlsym(library, name));
        if (!function && out.error.empty()) out.error = std::string("libxml2.so.2 has no ") + name;
    };
    get(x.InitParser, "xmlInitParser");
    get(x.SetExternalEntityLoader, "xmlSetExternalEntityLoader");
    get(x.SetGenericErrorFunc, "xmlSetGenericErrorFunc");
    get(x.CreatePushParserCtxt, "xmlCreatePushParserCtxt");
    get(x.CtxtUseOptions, "xmlCtxtUseOptions");
    get(x.ParseChunk, "xmlParseChunk");
    get(x.FreeDoc, "xmlFreeDoc");
    get(x.FreeParserCtxt, "xmlFreeParserCtxt");
    get(x.DictOwns, "xmlDictOwns");
    get(x.StopParser, "xmlStopParser");
    if (!out.error.empty()) return out;
    x.InitParser();
    x.SetExternalEntityLoader(refuse_external_entity);
    return out;
}

}  // namespace

const LibXml* libxml(std::string& error) {
    static const Loaded loaded = load();  // once, thread-safe
    if (!loaded.error.empty()) {
        error = loaded.error;
        return nullptr;
    }
    return &loaded.api;
}

}  // namespace vr
