// What the classic reader skips without reading: an unknown node type's body, and the value of a
// field it cannot type (an unknown field, a value given to an event), whatever the value's shape,
// so that the rest of the node is read as browsers read it (docs/input.md, "What is forgiven").
#pragma once
#include <string_view>

#include "parser/lexer.h"

namespace vr {

// Field and node names never start with a digit, a sign or a period: such a word is a number.
bool starts_identifier(std::string_view word);

// Skips a balanced { ... } or [ ... ] group whose opening token is next. Throws SyntaxError
// (parser/field_value.h) when there is none, or when the group or a string in it is not closed.
void skip_group(Lexer& lexer);

// Skips the value at the lexer, whatever its shape: a run of numbers, a bracketed list, a string,
// TRUE or FALSE, NULL, USE name, IS name, or a node ([DEF name] Type { ... }). A word that is none
// of these is the next field's name, and '}' the node's end: the value was empty, nothing is
// skipped.
void skip_unknown_value(Lexer& lexer);

}  // namespace vr
