// CAT02 chromatic adaptation.
#include <pipeline/colour/cat02.h>

namespace replica::pipeline::colour {

const Matrix3& cat02Forward()
{
    // CIE 159:2004, M_CAT02
    static const Matrix3 m{
            {{0.7328, 0.4296, -0.1624}, {-0.7036, 1.6975, 0.0061}, {0.0030, 0.0136, 0.9834}}};
    return m;
}

const Matrix3& cat02Inverse()
{
    static const Matrix3 m = inverse(cat02Forward());
    return m;
}

namespace {

bool allPositive(const Xyz& v)
{
    return v.x > 0.0 && v.y > 0.0 && v.z > 0.0;
}

// diag(D * d / s + 1 - D), the von Kries gains; s is positive in every component.
Matrix3 vonKriesGains(const Xyz& s, const Xyz& d, double degree)
{
    Matrix3 gains{};
    gains[0][0] = degree * d.x / s.x + 1.0 - degree;
    gains[1][1] = degree * d.y / s.y + 1.0 - degree;
    gains[2][2] = degree * d.z / s.z + 1.0 - degree;
    return gains;
}

} // namespace

bool cat02Defined(const Xyz& white)
{
    return allPositive(applyMatrix(cat02Forward(), white));
}

Adaptation adaptationBetween(const Xyz& sourceWhite, const Xyz& destinationWhite)
{
    if (cat02Defined(sourceWhite) && cat02Defined(destinationWhite)) {
        return Adaptation::Cat02;
    }
    if (allPositive(sourceWhite) && allPositive(destinationWhite)) {
        return Adaptation::XyzScaling;
    }
    return Adaptation::None;
}

Matrix3 cat02AdaptationMatrix(const Xyz& sourceWhite, const Xyz& destinationWhite, double degree)
{
    switch (adaptationBetween(sourceWhite, destinationWhite)) {
    case Adaptation::Cat02:
        return multiply(
                cat02Inverse(),
                multiply(vonKriesGains(applyMatrix(cat02Forward(), sourceWhite),
                                       applyMatrix(cat02Forward(), destinationWhite), degree),
                         cat02Forward()));
    case Adaptation::XyzScaling:
        return vonKriesGains(sourceWhite, destinationWhite, degree);
    case Adaptation::None:
        break;
    }
    return Matrix3{{{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}}};
}

Xyz cat02Adapt(const Xyz& xyz, const Xyz& sourceWhite, const Xyz& destinationWhite, double degree)
{
    return applyMatrix(cat02AdaptationMatrix(sourceWhite, destinationWhite, degree), xyz);
}

} // namespace replica::pipeline::colour
