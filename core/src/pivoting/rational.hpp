// core/src/pivoting/rational.hpp (internal): a tiny exact fraction for the Lemke tableau trace:
// int64 numerator and denominator, every intermediate in __int128, always reduced by the gcd. A
// result that does not fit in int64 throws RationalOverflow, so the caller can fall back to
// decimals and say so.
#pragma once

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace mlcp::detail {

struct RationalOverflow : std::overflow_error {
  RationalOverflow() : std::overflow_error("fraction does not fit in 64 bits") {}
};

class Rational {
 public:
  using Wide = __int128;

  Rational() = default;
  Rational(std::int64_t n) : num_(n) {}  // NOLINT: integers convert implicitly, as in math
  static Rational fromWide(Wide n, Wide d) {
    if (d == 0) throw std::domain_error("division by zero in a fraction");
    if (d < 0) n = -n, d = -d;
    const Wide g = gcd(n < 0 ? -n : n, d);
    if (g > 1) n /= g, d /= g;
    if (!fits(n) || !fits(d)) throw RationalOverflow();
    Rational r;
    r.num_ = static_cast<std::int64_t>(n);
    r.den_ = static_cast<std::int64_t>(d);
    return r;
  }
  // Whether v is an integer that converts exactly (|v| < 2^53).
  static bool isSmallInteger(double v) { return std::abs(v) < 9.0e15 && v == std::floor(v); }

  std::int64_t num() const { return num_; }
  std::int64_t den() const { return den_; }
  double toDouble() const { return static_cast<double>(num_) / static_cast<double>(den_); }
  std::string str() const {
    return den_ == 1 ? std::to_string(num_) : std::to_string(num_) + "/" + std::to_string(den_);
  }

  friend Rational operator+(const Rational& a, const Rational& b) {
    return fromWide(Wide(a.num_) * b.den_ + Wide(b.num_) * a.den_, Wide(a.den_) * b.den_);
  }
  friend Rational operator-(const Rational& a, const Rational& b) {
    return fromWide(Wide(a.num_) * b.den_ - Wide(b.num_) * a.den_, Wide(a.den_) * b.den_);
  }
  friend Rational operator*(const Rational& a, const Rational& b) {
    return fromWide(Wide(a.num_) * b.num_, Wide(a.den_) * b.den_);
  }
  friend Rational operator/(const Rational& a, const Rational& b) {
    return fromWide(Wide(a.num_) * b.den_, Wide(a.den_) * b.num_);
  }
  Rational operator-() const { return fromWide(-Wide(num_), den_); }
  friend bool operator<(const Rational& a, const Rational& b) {
    return Wide(a.num_) * b.den_ < Wide(b.num_) * a.den_;
  }
  friend bool operator==(const Rational& a, const Rational& b) {
    return a.num_ == b.num_ && a.den_ == b.den_;
  }

 private:
  static Wide gcd(Wide a, Wide b) {
    while (b != 0) {
      const Wide t = a % b;
      a = b;
      b = t;
    }
    return a;
  }
  static bool fits(Wide v) { return v <= INT64_MAX && v >= -INT64_MAX; }

  std::int64_t num_ = 0;
  std::int64_t den_ = 1;
};

}  // namespace mlcp::detail
