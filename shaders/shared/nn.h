// Push constants, binding slots and specialization ids of the U-Net passes (nn_conv.comp,
// nn_maxpool.comp, nn_upsample.comp), shared by GLSL and src/nn_kernels.
// Tensors are NCHW. A "view" is a channel slice [c0, c0 + C) of a buffer holding cTotal
// channels per map: that is how a skip concatenation is written without a copy.
// Storage is fp32 words, or fp16 packed two per 32-bit word (unpackHalf2x16), chosen per
// binding by a specialization constant; packed tensors need even widths (always true here).
#ifndef OSR_SHARED_NN_H
#define OSR_SHARED_NN_H
#include "shared/types.h"
OSR_NAMESPACE_BEGIN(nn)

OSR_CONST(uint, kBindingIn, 0);
OSR_CONST(uint, kBindingOut, 1);
OSR_CONST(uint, kBindingWeights, 2);  // conv only: [cin][ks*ks][coutPadded]
OSR_CONST(uint, kBindingParams, 3);   // conv only: fp32 bias[coutPadded], scale[..], shift[..]
OSR_CONST(uint, kBindingWeightTexels, 4);  // conv only: the weights as an RGBA texel buffer
OSR_CONST(uint, kBindingInTexels, 5);      // conv only: the input as RGBA texels (4 pixels each)
OSR_CONST(uint, kConvBindingCount, 6);
OSR_CONST(uint, kResampleBindingCount, 2);  // pool, upsample: kBindingIn, kBindingOut

// Specialization constant ids.
OSR_CONST(uint, kSpecWorkgroup, 0);   // local_size_x
OSR_CONST(uint, kSpecInHalf, 1);      // 1: input stored as packed fp16
OSR_CONST(uint, kSpecOutHalf, 2);     // 1: output stored as packed fp16
OSR_CONST(uint, kSpecWeightHalf, 3);  // conv: weights stored as packed fp16
OSR_CONST(uint, kSpecKernel, 4);      // conv: kernel size (3 or 1), padding kernel/2
OSR_CONST(uint, kSpecTileH, 5);       // conv: output rows per invocation
OSR_CONST(uint, kSpecTileW, 6);       // conv: output columns per invocation (even)
OSR_CONST(uint, kSpecActivation, 7);  // conv: kActNone / kActLeakyRelu / kActRelu
OSR_CONST(uint, kSpecBatchNorm, 8);   // conv: 1 applies scale/shift after the activation
OSR_CONST(uint, kSpecSlope, 9);       // conv: LeakyReLU negative slope (float)
OSR_CONST(uint, kSpecShare, 10);      // conv: lanes sharing input loads (subgroup size), 0: none
OSR_CONST(uint, kSpecWeightTexel, 11);  // conv: 1 reads weights through the texel binding
OSR_CONST(uint, kSpecInTexel, 12);      // conv: 1 reads shared input loads as texels

OSR_CONST(uint, kActNone, 0);
OSR_CONST(uint, kActLeakyRelu, 1);
OSR_CONST(uint, kActRelu, 2);

// Elementwise passes (pool, upsample): one invocation per pair of adjacent output pixels.
OSR_CONST(uint, kElementwiseWorkgroup, 64);

// A channel slice of an NCHW tensor: element (n, c, y, x) of the view is word/half index
// ((n * cTotal + c0 + c) * h + y) * w + x of the bound range.
struct View {
  uint cTotal;
  uint c0;
  uint _pad0;
  uint _pad1;
};

struct ConvPush {
  View src;
  View dst;
  uint maps;        // N in this dispatch
  uint cin;
  uint cout;
  uint coutPadded;  // weights/params row length (multiple of the workgroup size)
  uint height;      // input = output size as stored (multiples of the tile)
  uint width;
  uint tileCount;   // maps * (height / tileH) * (width / tileW)
  uint tileGroupsY; // tile index = groupId.y + groupId.z * tileGroupsY
  // The valid top-left region of the stored size: outputs outside it are stored as zero, so
  // a tensor padded to the tile holds exactly the zero padding its readers expect.
  uint validHeight;
  uint validWidth;
  uint _pad0;
  uint _pad1;
};

// 2x2 max-pool, stride 2; also bilinear x2 upsample. Sizes as stored; the valid input region
// (top left) maps to valid outputs (half or twice it); outputs outside theirs are stored as 0.
struct PoolPush {
  View src;
  View dst;
  uint maps;
  uint channels;
  uint inHeight;
  uint inWidth;
  uint outHeight;
  uint outWidth;   // even
  uint validInHeight;
  uint validInWidth;
  uint pairCount;  // maps * channels * outHeight * outWidth / 2
  uint groupsX;    // pair index = (groupId.x + groupId.y * groupsX) * workgroup + local id
  uint _pad0;
  uint _pad1;
};

OSR_NAMESPACE_END
#endif
