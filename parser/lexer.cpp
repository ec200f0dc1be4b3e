#include "parser/lexer.h"

namespace vr {

std::string Lexer::describe(const Token& t) const {
    switch (t.kind) {
        case TokenKind::End:
            return "end of file";
        case TokenKind::LBrace:
            return "'{'";
        case TokenKind::RBrace:
            return "'}'";
        case TokenKind::LBracket:
            return "'['";
        case TokenKind::RBracket:
            return "']'";
        case TokenKind::BadString:
            return "an unterminated string";
        case TokenKind::String:  // quoted as written: '"two"' says both what and which
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
