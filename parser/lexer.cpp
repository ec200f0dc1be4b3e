#include "parser/lexer.h"

namespace vr {
namespace {

// Bytes that end a word. Everything else (including UTF-8 sequences) belongs to words.
struct SeparatorTable {
    bool sep[256] = {};
    constexpr SeparatorTable() {
        for (int c = 0; c <= 0x20; ++c) sep[c] = true;
        sep[static_cast<unsigned char>(',')] = true;
        sep[static_cast<unsigned char>('"')] = true;
        sep[static_cast<unsigned char>('#')] = true;
        sep[static_cast<unsigned char>('{')] = true;
        sep[static_cast<unsigned char>('}')] = true;
        sep[static_cast<unsigned char>('[')] = true;
        sep[static_cast<unsigned char>(']')] = true;
        sep[0x7f] = true;
    }
};
constexpr SeparatorTable kSeparators;

inline bool is_space(unsigned char c) { return c <= 0x20 || c == ',' || c == 0x7f; }

}  // namespace

Lexer::Lexer(std::string_view text, uint32_t begin, uint32_t end)
    : text_(text), pos_(begin), end_(end > text.size() ? static_cast<uint32_t>(text.size()) : end) {}

Token Lexer::scan() {
    const char* s = text_.data();
    for (;;) {
        while (pos_ < end_ && is_space(static_cast<unsigned char>(s[pos_]))) ++pos_;
        if (pos_ < end_ && s[pos_] == '#') {
            while (pos_ < end_ && s[pos_] != '\n' && s[pos_] != '\r') ++pos_;
            continue;
        }
        break;
    }
    Token t;
    t.offset = pos_;
    if (pos_ >= end_) {
        t.kind = TokenKind::End;
        return t;
    }
    char c = s[pos_];
    switch (c) {
        case '{': t.kind = TokenKind::LBrace; t.length = 1; ++pos_; return t;
        case '}': t.kind = TokenKind::RBrace; t.length = 1; ++pos_; return t;
        case '[': t.kind = TokenKind::LBracket; t.length = 1; ++pos_; return t;
        case ']': t.kind = TokenKind::RBracket; t.length = 1; ++pos_; return t;
        case '"': {
            uint32_t p = pos_ + 1;
            while (p < end_ && s[p] != '"') {
                if (s[p] == '\\' && p + 1 < end_) ++p;
                ++p;
            }
            if (p >= end_) {
                t.kind = TokenKind::BadString;
                t.length = end_ - pos_;
                pos_ = end_;
                return t;
            }
            t.kind = TokenKind::String;
            t.length = p + 1 - pos_;
            pos_ = p + 1;
            return t;
        }
        default: break;
    }
    uint32_t p = pos_;
    while (p < end_ && !kSeparators.sep[static_cast<unsigned char>(s[p])]) ++p;
    t.kind = TokenKind::Word;
    t.length = p - pos_;
    pos_ = p;
    return t;
}

std::string Lexer::describe(const Token& t) const {
    switch (t.kind) {
        case TokenKind::End: return "end of file";
        case TokenKind::LBrace: return "'{'";
        case TokenKind::RBrace: return "'}'";
        case TokenKind::LBracket: return "'['";
        case TokenKind::RBracket: return "']'";
        case TokenKind::String: return "a string";
        case TokenKind::BadString: return "an unterminated string";
        case TokenKind::Word: {
            std::string_view w = text(t);
            return "'" + std::string(w.substr(0, 40)) + (w.size() > 40 ? "...'" : "'");
        }
    }
    return "?";
}

std::string Lexer::unescape(std::string_view quoted) {
    std::string out;
    if (quoted.size() < 2) return out;
    std::string_view body = quoted.substr(1, quoted.size() - 2);
    out.reserve(body.size());
    for (size_t i = 0; i < body.size(); ++i) {
        if (body[i] == '\\' && i + 1 < body.size()) ++i;
        out += body[i];
    }
    return out;
}

}  // namespace vr
