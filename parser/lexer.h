// Tokens of the classic encodings (VRML97, X3D classic, VRML 1.0). Tokens keep byte offsets only;
// line and column are computed when a message is printed.
#pragma once
#include <cstdint>
#include <string>
#include <string_view>

namespace vr {

enum class TokenKind : uint8_t {
    Word,       // identifiers, keywords, numbers: a run of characters up to a separator
    String,     // "..." (offset/length include the quotes)
    LBrace,     // {
    RBrace,     // }
    LBracket,   // [
    RBracket,   // ]
    End,
    BadString,  // a string that runs to the end of the file
};

struct Token {
    TokenKind kind = TokenKind::End;
    uint32_t offset = 0;
    uint32_t length = 0;
};

// Reads tokens from [begin, end) of a text. Commas are white space; '#' starts a comment.
class Lexer {
public:
    Lexer(std::string_view text, uint32_t begin, uint32_t end);
    explicit Lexer(std::string_view text) : Lexer(text, 0, static_cast<uint32_t>(text.size())) {}

    const Token& peek() {
        if (!has_peek_) {
            peeked_ = scan();
            has_peek_ = true;
        }
        return peeked_;
    }
    Token next() {
        Token t = peek();
        has_peek_ = false;
        return t;
    }
    std::string_view text(const Token& t) const { return text_.substr(t.offset, t.length); }
    // Offset of the next token (after skipping white space and comments).
    uint32_t next_offset() { return peek().offset; }

    // A token as an error message names it: "end of file", "'{'", "a string", "'word'" (cut at 40 bytes).
    std::string describe(const Token& t) const;

    // The value of a String token: quotes removed, \" and \\ unescaped.
    static std::string unescape(std::string_view quoted);

private:
    Token scan();
    std::string_view text_;
    uint32_t pos_;
    uint32_t end_;
    Token peeked_;
    bool has_peek_ = false;
};

}  // namespace vr
