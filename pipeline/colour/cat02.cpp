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

Matrix3 cat02AdaptationMatrix(const Xyz& sourceWhite, const Xyz& destinationWhite, double degree)
{
    const Xyz rs = applyMatrix(cat02Forward(), sourceWhite);
    const Xyz rd = applyMatrix(cat02Forward(), destinationWhite);
    Matrix3 identity{{{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}}};
    if (!(rs.x > 0.0 && rs.y > 0.0 && rs.z > 0.0 && rd.x > 0.0 && rd.y > 0.0 && rd.z > 0.0)) {
        return identity;
    }
    Matrix3 scale{};
    scale[0][0] = degree * rd.x / rs.x + 1.0 - degree;
    scale[1][1] = degree * rd.y / rs.y + 1.0 - degree;
    scale[2][2] = degree * rd.z / rs.z + 1.0 - degree;
    return multiply(cat02Inverse(), multiply(scale, cat02Forward()));
}

Xyz cat02Adapt(const Xyz& xyz, const Xyz& sourceWhite, const Xyz& destinationWhite, double degree)
{
    return applyMatrix(cat02AdaptationMatrix(sourceWhite, destinationWhite, degree), xyz);
}

} // namespace replica::pipeline::colour
