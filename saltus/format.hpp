// Numbers and names in the text Saltus writes (reports, CSV headers, messages).
#pragma once

#include <string>

namespace saltus {

// %.{digits}g; "nan", "inf", "-inf"; never "-0".
std::string formatNumber(double x, int digits = 6);

// CSV-quotes a field when it holds a comma, quote or newline (newlines become spaces).
std::string csvField(const std::string& s);

}  // namespace saltus
