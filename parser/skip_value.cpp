#include "parser/skip_value.h"

#include <cctype>
#include <string>

#include "parser/field_value.h"

namespace vr {
namespace {

[[noreturn]] void fail(const Token& t, std::string message) {
    throw SyntaxError{t.offset, std::move(message)};
}

}  // namespace

bool starts_identifier(std::string_view word) {
    const char c = word.front();
    return !std::isdigit(static_cast<unsigned char>(c)) && c != '+' && c != '-' && c != '.';
}

void skip_group(Lexer& lexer) {
    const Token open = lexer.next();
    if (open.kind != TokenKind::LBrace && open.kind != TokenKind::LBracket)
        fail(open, "expected '{' or '[', found " + lexer.describe(open));
    size_t depth = 1;
    while (depth > 0) {
        const Token t = lexer.next();
        switch (t.kind) {
            case TokenKind::LBrace:
            case TokenKind::LBracket:
                ++depth;
                break;
            case TokenKind::RBrace:
            case TokenKind::RBracket:
                --depth;
                break;
            case TokenKind::End:
                fail(open, "this group is not closed before the end of the file");
            case TokenKind::BadString:
                fail(t, "string is not closed before the end of the file");
            default:
                break;
        }
    }
}

void skip_unknown_value(Lexer& lexer) {
    const Token t = lexer.peek();
    switch (t.kind) {
        case TokenKind::LBracket:
        case TokenKind::LBrace:
            skip_group(lexer);
            return;
        case TokenKind::String:
            lexer.next();
            return;
        case TokenKind::BadString:
            fail(t, "string is not closed before the end of the file");
        case TokenKind::Word:
            break;
        default:
            return;  // '}', ']' or the end: the node's end says what is wrong
    }
    const std::string_view w = lexer.text(t);
    if (!starts_identifier(w)) {
        while (lexer.peek().kind == TokenKind::Word && !starts_identifier(lexer.text(lexer.peek())))
            lexer.next();
        return;
    }
    if (w == "NULL" || w == "TRUE" || w == "FALSE") {
        lexer.next();
        return;
    }
    if (w == "USE" || w == "IS") {
        lexer.next();
        const Token name = lexer.next();
        if (name.kind != TokenKind::Word)
            fail(name, std::string("expected a name after ") + std::string(w) + ", found " +
                           lexer.describe(name));
        return;
    }
    // A node: a word with '{' after it ([DEF name] Type {).
    const int words = w == "DEF" ? 3 : 1;
    Lexer probe = lexer;
    for (int i = 0; i < words; ++i) probe.next();
    if (probe.peek().kind != TokenKind::LBrace) return;
    for (int i = 0; i < words; ++i) lexer.next();
    skip_group(lexer);
}

}  // namespace vr
