// UTF-8 validation (util/utf8.hpp): well-formed text passes, each kind of malformed sequence is found at its lead byte.
#include <catch2/catch.hpp>

#include <string>

#include "fibernet/util/utf8.hpp"

using fibernet::invalid_utf8_at;

TEST_CASE("utf8: well-formed text is accepted", "[utf8]") {
    CHECK(invalid_utf8_at("") == std::string::npos);
    CHECK(invalid_utf8_at("0 -1.0  # alpha\n90 0\n") == std::string::npos);
    CHECK(invalid_utf8_at("# r\xc3\xa9sultats, \xe2\x82\xac, \xf0\x9f\x98\x80") == std::string::npos);  // é, €, emoji
    CHECK(invalid_utf8_at("\xf4\x8f\xbf\xbf") == std::string::npos);  // U+10FFFF, the largest code point
}

TEST_CASE("utf8: malformed sequences are found at their first byte", "[utf8]") {
    CHECK(invalid_utf8_at("ab\xff") == 2);               // never a UTF-8 byte
    CHECK(invalid_utf8_at("# r\xe9sultats") == 3);       // Latin-1 é
    CHECK(invalid_utf8_at("x\xc3") == 1);                // truncated at the end
    CHECK(invalid_utf8_at("\xc3(") == 0);                // bad continuation
    CHECK(invalid_utf8_at("\xc0\xaf") == 0);             // overlong '/'
    CHECK(invalid_utf8_at("\xe0\x80\xaf") == 0);         // overlong, 3 bytes
    CHECK(invalid_utf8_at("\xed\xa0\x80") == 0);         // a surrogate
    CHECK(invalid_utf8_at("\xf4\x90\x80\x80") == 0);     // above U+10FFFF
    CHECK(invalid_utf8_at("ok \x80") == 3);              // a lone continuation byte
}
