// Tokens of the classic encodings (VRML97, X3D classic, VRML 1.0). Tokens keep byte offsets only;
// line and column are computed when a message is printed.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "parser/source.h"

namespace vr {

enum class TokenKind : uint8_t {
    Word,      // identifiers, keywords, numbers: a run of characters up to a separator
    String,    // "..." (offset/length include the quotes)
    LBrace,    // {
    RBrace,    // }
    LBracket,  // [
    RBracket,  // ]
    End,
    BadString,  // a string that runs to the end of the file
};

struct Token {
    TokenKind kind = TokenKind::End;
    SourceOffset offset = 0;
    SourceOffset length = 0;  // a string may run to the end of a file of any size
};

// Byte classes of the classic encodings. Word bytes are all that end no word (UTF-8 sequences too).
enum class CharClass : uint8_t { Word, Space, Hash, Quote, LBrace, RBrace, LBracket, RBracket };

struct CharClassTable {
    CharClass of[256] = {};
    constexpr CharClassTable() {
        for (int c = 0; c <= 0x20; ++c) of[c] = CharClass::Space;
        of[static_cast<unsigned char>(',')] = CharClass::Space;  // commas are white space
        of[0x7f] = CharClass::Space;
        of[static_cast<unsigned char>('#')] = CharClass::Hash;
        of[static_cast<unsigned char>('"')] = CharClass::Quote;
        of[static_cast<unsigned char>('{')] = CharClass::LBrace;
        of[static_cast<unsigned char>('}')] = CharClass::RBrace;
        of[static_cast<unsigned char>('[')] = CharClass::LBracket;
        of[static_cast<unsigned char>(']')] = CharClass::RBracket;
    }
};
inline constexpr CharClassTable kCharClass;

// A word that may be a plain decimal number: [+-]digits[.digits]. Lexer::next_number reads its
// value while it finds the word's end, so the bytes of the numbers that fill big files are looked
// at once.
struct Decimal {
    bool plain = false;  // the token is a word of this form with 1 to 19 digits
    bool negative = false;
    int32_t fraction = -1;  // digits after the point; -1: no point
    uint64_t digits = 0;    // all digits as one integer (exact: at most 19 of them)

    // The value when digits <= 2^53 and fraction <= 22: then digits and 10^fraction are both exact
    // doubles and one division rounds correctly, so it is the value std::from_chars gives
    // (Clinger's fast path). False for the rest, which the caller reads the general way.
    bool to_double(double& out) const {
        static constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                            1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                            1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
        if (!plain || digits > (uint64_t(1) << 53) || fraction > 22) return false;
        const double v = static_cast<double>(digits) / kPow10[fraction < 0 ? 0 : fraction];
        out = negative ? -v : v;
        return true;
    }
};

// Reads [+-]digits[.digits] from p and returns where it stopped; fills d (plain) when that was 1 to
// 19 digits. Whether the word ends there is the caller's question.
inline const unsigned char* read_decimal(const unsigned char* p, const unsigned char* e,
                                         Decimal& d) {
    const bool negative = p < e && *p == '-';
    if (p < e && (*p == '-' || *p == '+')) ++p;
    const unsigned char* const first = p;
    uint64_t m = 0;
    for (; p < e && static_cast<unsigned char>(*p - '0') < 10; ++p)
        m = m * 10 + static_cast<unsigned char>(*p - '0');
    const unsigned char* point = nullptr;
    if (p < e && *p == '.') {
        point = p++;
        for (; p < e && static_cast<unsigned char>(*p - '0') < 10; ++p)
            m = m * 10 + static_cast<unsigned char>(*p - '0');
    }
    const ptrdiff_t count = p - first - (point ? 1 : 0);  // leading zeros too: 19 cannot overflow m
    d.plain = count > 0 && count <= 19;
    d.negative = negative;
    d.fraction = point ? static_cast<int32_t>(p - point - 1) : -1;
    d.digits = m;
    return p;
}

// Reads tokens from [begin, end) of a text. Commas are white space; '#' starts a comment.
// The scanner is inline: readers call it once per token, and a big file's reading time is mostly
// here. A peeked token has its decimal read too, because the token after a field name is usually a
// number.
class Lexer {
  public:
    Lexer(std::string_view text, SourceOffset begin, SourceOffset end)
        : text_(text), pos_(begin), end_(end > text.size() ? text.size() : end) {}
    explicit Lexer(std::string_view text) : Lexer(text, 0, text.size()) {}

    const Token& peek() {
        if (!has_peek_) {
            scan<true>(peeked_, peeked_decimal_);
            has_peek_ = true;
        }
        return peeked_;
    }
    Token next() {
        if (has_peek_) {
            has_peek_ = false;
            return peeked_;
        }
        Token t;
        Decimal unused;
        scan<false>(t, unused);
        return t;
    }
    // The next token, as next() gives it; when it is a plain decimal word, `d` holds its value's
    // parts.
    Token next_number(Decimal& d) {
        if (has_peek_) {
            has_peek_ = false;
            d = peeked_decimal_;
            return peeked_;
        }
        Token t;
        scan<true>(t, d);
        return t;
    }
    std::string_view text(const Token& t) const { return {text_.data() + t.offset, t.length}; }
    // Offset of the next token (after skipping white space and comments).
    SourceOffset next_offset() { return peek().offset; }
    // Offset up to which the text has been read (the end of the last token scanned).
    SourceOffset position() const { return pos_; }
    bool has_peek() const { return has_peek_; }
    std::string_view source() const { return text_; }
    SourceOffset source_end() const { return end_; }

    // A token as an error message names it: "end of file", "'{'", "a string", "'word'" (cut at 40
    // bytes).
    std::string describe(const Token& t) const;

    // The value of a String token: quotes removed, \" and \\ unescaped.
    static std::string unescape(std::string_view quoted);

  private:
    // First byte at or after p that is not white space or inside a comment.
    static const unsigned char* skip_space(const unsigned char* p, const unsigned char* e) {
        // Byte by byte: runs of white space and words are a few bytes long, too short for SIMD to
        // pay.
        for (;;) {
            while (p < e && kCharClass.of[*p] == CharClass::Space) ++p;
            if (p < e && *p == '#') {
                while (p < e && *p != '\n' && *p != '\r') ++p;
                continue;
            }
            return p;
        }
    }

    // First byte at or after q that ends a word.
    static const unsigned char* word_end(const unsigned char* q, const unsigned char* e) {
        while (q < e && kCharClass.of[*q] == CharClass::Word) ++q;
        return q;
    }

    // Reads the next token into t; with kDecimals, a word that starts like a number is also read as
    // one into d (d.plain says whether it is a plain decimal), in the same pass over its bytes.
    template <bool kDecimals>
    void scan(Token& t, Decimal& d) {
        d.plain = false;
        const auto* s = reinterpret_cast<const unsigned char*>(text_.data());
        const unsigned char* const e = s + end_;
        const unsigned char* p = skip_space(s + pos_, e);
        t.offset = static_cast<SourceOffset>(p - s);
        if (p >= e) {
            t.kind = TokenKind::End;
            t.length = 0;
            pos_ = t.offset;
            return;
        }
        const unsigned char* q = p + 1;
        switch (kCharClass.of[*p]) {
            case CharClass::Word:
                if (kDecimals && is_number_start(*p))
                    q = decimal_word(p, e, d);
                else
                    q = word_end(q, e);
                t.kind = TokenKind::Word;
                break;
            case CharClass::LBrace:
                t.kind = TokenKind::LBrace;
                break;
            case CharClass::RBrace:
                t.kind = TokenKind::RBrace;
                break;
            case CharClass::LBracket:
                t.kind = TokenKind::LBracket;
                break;
            case CharClass::RBracket:
                t.kind = TokenKind::RBracket;
                break;
            default:
                scan_string(q, e, t);
                break;  // '"' (white space and '#' were skipped above)
        }
        t.length = static_cast<SourceOffset>(q - p);
        pos_ = static_cast<SourceOffset>(q - s);
    }

    static bool is_number_start(unsigned char c) {
        return static_cast<unsigned char>(c - '0') < 10 || c == '-' || c == '+' || c == '.';
    }

    // Reads the word at p (which starts like a number) and returns its end; d.plain when the whole
    // word is a plain decimal.
    static const unsigned char* decimal_word(const unsigned char* p, const unsigned char* e,
                                             Decimal& d) {
        const unsigned char* q = read_decimal(p, e, d);
        if (q < e && kCharClass.of[*q] == CharClass::Word) {  // "1e5", "0x1F", "-inf"
            d.plain = false;
            return word_end(q, e);
        }
        return q;
    }

    // After an opening quote: moves q past the closing one, or to the end of the text (BadString).
    static void scan_string(const unsigned char*& q, const unsigned char* e, Token& t) {
        while (q < e && *q != '"') {
            if (*q == '\\' && q + 1 < e) ++q;
            ++q;
        }
        if (q >= e) {
            t.kind = TokenKind::BadString;
            q = e;
            return;
        }
        t.kind = TokenKind::String;
        ++q;
    }

    std::string_view text_;
    SourceOffset pos_;
    SourceOffset end_;
    Token peeked_;
    Decimal peeked_decimal_;
    bool has_peek_ = false;
};

}  // namespace vr
