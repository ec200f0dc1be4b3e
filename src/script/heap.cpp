#include "script/heap.h"

#include <cstdlib>
#include <cstring>

#include "duktape.h"

// Duktape's execution-timeout check (DUK_USE_EXEC_TIMEOUT_CHECK in the build's duk_config.h):
// true ends the running call with a RangeError, again and again until it has unwound, so a
// script's own catch cannot keep it going.
extern "C" int vrmlray_duk_timeout(void* udata) {
    auto* heap = static_cast<vr::ScriptHeap*>(udata);
    if (!heap || std::chrono::steady_clock::now() < heap->deadline) return 0;
    heap->timed_out = heap->interrupted = true;
    return 1;
}

namespace vr {
namespace {

// Each block carries its size in front, so that the budget counts what is freed too.
constexpr size_t kHeader = alignof(std::max_align_t);

// A call past its deadline gets no more memory: a loop whose time goes into native code (a long
// Array.join each turn) runs few bytecode instructions between the interrupt counter's checks,
// but it allocates; refused, it ends with Duktape's preallocated DoubleError. Once the counter's
// check has said so, the RangeError that ends the call (naming the line) gets its memory.
bool over_time(ScriptHeap& heap) {
    if (heap.interrupted || heap.deadline == std::chrono::steady_clock::time_point::max() ||
        std::chrono::steady_clock::now() < heap.deadline)
        return false;
    heap.timed_out = true;
    return true;
}

void* budget_alloc(void* udata, duk_size_t size) {
    auto* heap = static_cast<ScriptHeap*>(udata);
    if (size == 0) return nullptr;
    // Over the budget Duktape collects garbage, then throws "alloc failed".
    if (heap->bytes + size > heap->limits.heap_bytes || over_time(*heap)) return nullptr;
    auto* block = static_cast<unsigned char*>(std::malloc(size + kHeader));
    if (!block) return nullptr;
    std::memcpy(block, &size, sizeof size);
    heap->bytes += size;
    return block + kHeader;
}

void budget_free(void* udata, void* ptr) {
    if (!ptr) return;
    auto* heap = static_cast<ScriptHeap*>(udata);
    unsigned char* block = static_cast<unsigned char*>(ptr) - kHeader;
    size_t size = 0;
    std::memcpy(&size, block, sizeof size);
    heap->bytes -= size;
    std::free(block);
}

void* budget_realloc(void* udata, void* ptr, duk_size_t size) {
    if (!ptr) return budget_alloc(udata, size);
    if (size == 0) {
        budget_free(udata, ptr);
        return nullptr;
    }
    auto* heap = static_cast<ScriptHeap*>(udata);
    unsigned char* block = static_cast<unsigned char*>(ptr) - kHeader;
    size_t old = 0;
    std::memcpy(&old, block, sizeof old);
    if (size > old && (heap->bytes + (size - old) > heap->limits.heap_bytes || over_time(*heap)))
        return nullptr;
    auto* grown = static_cast<unsigned char*>(std::realloc(block, size + kHeader));
    if (!grown) return nullptr;
    std::memcpy(grown, &size, sizeof size);
    heap->bytes = heap->bytes - old + size;
    return grown + kHeader;
}

// Duktape's fatal errors (out of memory where it cannot throw) must not return: back to the
// call's setjmp, and the heap is never touched again.
void fatal(void* udata, const char* message) {
    auto* heap = static_cast<ScriptHeap*>(udata);
    heap->broken = true;
    heap->fatal_message = message ? message : "fatal error";
    if (heap->fatal_exit) std::longjmp(*heap->fatal_exit, 1);
    std::abort();  // outside a call (heap creation): nothing to return to
}

}  // namespace

ScriptHeap::ScriptHeap(const ScriptLimits& l) : limits(l) {
    ctx = duk_create_heap(budget_alloc, budget_realloc, budget_free, this, fatal);
}

ScriptHeap::~ScriptHeap() {
    // A heap whose fatal handler ran is in no state to be freed: its memory is left.
    if (ctx && !broken) duk_destroy_heap(ctx);
}

}  // namespace vr
