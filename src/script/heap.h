// One Duktape heap a Script (docs/scripts.md): its memory counted against a byte budget, its
// calls against a deadline. Duktape's interrupt counter (built in by CMakeLists.txt) asks
// vrmlray_duk_timeout() every few thousand bytecode instructions whether the call may go on.
#pragma once
#include <chrono>
#include <csetjmp>
#include <cstddef>
#include <string>

struct duk_hthread;
typedef struct duk_hthread duk_context;

namespace vr {

struct ScriptLimits {
    double seconds_per_call = 1.0;         // initialize(), an event function, eventsProcessed()
    size_t heap_bytes = size_t(64) << 20;  // all a Script's objects together
};

struct ScriptHeap {
    explicit ScriptHeap(const ScriptLimits& limits);
    ~ScriptHeap();
    ScriptHeap(const ScriptHeap&) = delete;
    ScriptHeap& operator=(const ScriptHeap&) = delete;

    duk_context* ctx = nullptr;
    ScriptLimits limits;
    size_t bytes = 0;  // allocated now
    std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
    bool timed_out = false;    // the last call passed its deadline
    bool interrupted = false;  // and the interrupt counter's check said so
    bool broken = false;       // Duktape called its fatal handler: the heap is never used again
    std::jmp_buf* fatal_exit = nullptr;
    std::string fatal_message;
};

}  // namespace vr
