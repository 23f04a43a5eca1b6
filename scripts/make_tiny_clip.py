#!/usr/bin/python3
"""Writes the tiny CLIP test fixture of op2gs's C++ CLIP (tests/fixtures/tiny_clip).

A CLIP of the ViT-B/16 architecture with random weights, a few layers and a
small width, stored exactly as the `openai/clip-vit-base-patch16` release
stores its files (model.safetensors with the Hugging Face tensor names,
config.json, vocab.json, merges.txt), and reference.json: what this script's
PyTorch reference computes from it (token IDs of tricky strings, image and text
embeddings), which the C++ tests must reproduce.

Needs Debian's python3-torch and python3-regex (run with /usr/bin/python3).
The reference is written independently of the C++ code:
  - the tokenizer follows OpenAI's simple_tokenizer.py (byte-level BPE), with
    ftfy.fix_text replaced by NFC normalisation (ftfy is not in Debian; op2gs
    documents the same choice);
  - the encoders follow the Hugging Face CLIPModel forward pass, in float64.

Usage: /usr/bin/python3 scripts/make_tiny_clip.py [OUT_DIR]
"""

import collections
import html
import json
import math
import os
import re
import struct
import sys
import unicodedata

import regex
import torch

SEED = 7
VISION = dict(hidden_size=48, intermediate_size=192, num_attention_heads=4,
              num_hidden_layers=2, image_size=32, patch_size=8)
TEXT = dict(hidden_size=32, intermediate_size=128, num_attention_heads=4,
            num_hidden_layers=2, max_position_embeddings=77)
PROJECTION_DIM = 24
NUM_MERGES = 400

# Text the fixture's BPE merges are learned from (any English text will do).
CORPUS = """
a photo of a red chair next to the wooden table. the green apple and the
yellow banana are on the kitchen counter. a small teapot, a blue cup, a glass
bottle of water, the old bag of cookies, a rubber duck, a jake figurine, the
toy elephant, sheep and porcelain hand, a waldo picture, the pink ice cream,
spatula, knife, bowl of ramen, chopsticks, egg, nori, onion segments, plate,
glass of water, napkin, pork belly, wavy noodles, kamaboko, corn, sake cup.
the quick brown fox jumps over the lazy dog while the cat sleeps on the sofa.
"""

# Strings whose token IDs the C++ tokenizer must reproduce.
TRICKY_STRINGS = [
    "a photo of a red chair",
    "  The   RED   Chair!!  ",
    "don't stop: it's the bag's handle, isn't it? we'll see; they've gone",
    "Hello, world... (yes) [no] {maybe} <tag> 50% off $3.99 #1 @home",
    "caf\u00e9 cre\u0300me br\u00fbl\u00e9e na\u00efve \u00fcber",
    "\u65e5\u672c\u8a9e\u306e\u30c6\u30ad\u30b9\u30c8 \u4e2d\u6587 \ud55c\uad6d\uc5b4",
    "emoji \U0001F600\U0001F4A9 and \u2603 snowman \u00bd \u00b2 \u2167",
    "tabs\tand\nnewlines\r\nand\u00a0nbsp\u2003em space",
    "fish &amp; chips &lt;3 &quot;quoted&quot; &#39;single&#39; &#x263A;",
    "\u0130stanbul \u03a3\u039f\u03a6\u039f\u03a3 STRASSE stra\u00dfe",
    "123 4567 3.14159 1,000,000 2nd 3rd",
    "<|startoftext|>literal special<|endoftext|> tokens",
    "",
    " ".join(["long"] * 40) + " text truncated at seventy seven tokens " * 3,
]

TEXTS_TO_ENCODE = ["a photo of a red chair", "the green apple", "", "don't!",
                   " ".join(["word"] * 90)]


# ---------------------------------------------------------------- tokenizer

def bytes_to_unicode():
    bs = (list(range(ord("!"), ord("~") + 1)) + list(range(ord("\u00a1"), ord("\u00ac") + 1)) +
          list(range(ord("\u00ae"), ord("\u00ff") + 1)))
    cs = bs[:]
    n = 0
    for b in range(256):
        if b not in bs:
            bs.append(b)
            cs.append(256 + n)
            n += 1
    return dict(zip(bs, [chr(c) for c in cs]))


PATTERN = regex.compile(
    r"""<\|startoftext\|>|<\|endoftext\|>|'s|'t|'re|'ve|'m|'ll|'d|[\p{L}]+|[\p{N}]|[^\s\p{L}\p{N}]+""",
    regex.IGNORECASE)


def clean(text):
    text = unicodedata.normalize("NFC", text)
    text = html.unescape(html.unescape(text)).strip()
    return re.sub(r"\s+", " ", text).strip().lower()


def words_of(text):
    byte_encoder = bytes_to_unicode()
    return ["".join(byte_encoder[b] for b in w.encode("utf-8"))
            for w in PATTERN.findall(clean(text))]


def learn_merges(corpus, count):
    words = collections.Counter()
    for w in words_of(corpus):
        words[tuple(w[:-1]) + (w[-1] + "</w>",)] += 1
    merges = []
    for _ in range(count):
        pairs = collections.Counter()
        for word, freq in words.items():
            for a, b in zip(word, word[1:]):
                pairs[(a, b)] += freq
        if not pairs:
            break
        best = max(pairs.items(), key=lambda kv: (kv[1], kv[0]))[0]
        merges.append(best)
        merged = collections.Counter()
        for word, freq in words.items():
            out, i = [], 0
            while i < len(word):
                if i + 1 < len(word) and (word[i], word[i + 1]) == best:
                    out.append(word[i] + word[i + 1])
                    i += 2
                else:
                    out.append(word[i])
                    i += 1
            merged[tuple(out)] += freq
        words = merged
    return merges


class Tokenizer:
    def __init__(self, vocab, merges):
        self.encoder = vocab
        self.ranks = {m: i for i, m in enumerate(merges)}

    def bpe(self, token):
        if token in ("<|startoftext|>", "<|endoftext|>"):
            return (token,)  # simple_tokenizer's pre-filled cache
        word = tuple(token[:-1]) + (token[-1] + "</w>",)
        while len(word) > 1:
            pairs = set(zip(word, word[1:]))
            bigram = min(pairs, key=lambda p: self.ranks.get(p, float("inf")))
            if bigram not in self.ranks:
                break
            first, second = bigram
            out, i = [], 0
            while i < len(word):
                try:
                    j = word.index(first, i)
                except ValueError:
                    out.extend(word[i:])
                    break
                out.extend(word[i:j])
                i = j
                if word[i] == first and i < len(word) - 1 and word[i + 1] == second:
                    out.append(first + second)
                    i += 2
                else:
                    out.append(word[i])
                    i += 1
            word = tuple(out)
        return word

    def encode(self, text, context_length=77):
        ids = [self.encoder["<|startoftext|>"]]
        for w in words_of(text):
            ids.extend(self.encoder[t] for t in self.bpe(w))
        ids.append(self.encoder["<|endoftext|>"])
        if len(ids) > context_length:
            ids = ids[:context_length]
            ids[-1] = self.encoder["<|endoftext|>"]
        return ids


# ------------------------------------------------------------------- model

def random_weights(vocab_size, gen):
    def normal(*shape, std=0.1):
        return torch.randn(*shape, generator=gen) * std

    w = {}

    def layers(prefix, width, inner, count):
        for i in range(count):
            p = f"{prefix}.encoder.layers.{i}."
            for name in ("q_proj", "k_proj", "v_proj", "out_proj"):
                w[p + f"self_attn.{name}.weight"] = normal(width, width, std=1 / math.sqrt(width))
                w[p + f"self_attn.{name}.bias"] = normal(width)
            for ln in ("layer_norm1", "layer_norm2"):
                w[p + f"{ln}.weight"] = 1 + normal(width)
                w[p + f"{ln}.bias"] = normal(width)
            w[p + "mlp.fc1.weight"] = normal(inner, width, std=1 / math.sqrt(width))
            w[p + "mlp.fc1.bias"] = normal(inner)
            w[p + "mlp.fc2.weight"] = normal(width, inner, std=1 / math.sqrt(inner))
            w[p + "mlp.fc2.bias"] = normal(width)

    v, t = VISION, TEXT
    vw, tw = v["hidden_size"], t["hidden_size"]
    patches = (v["image_size"] // v["patch_size"]) ** 2
    w["vision_model.embeddings.class_embedding"] = normal(vw, std=0.5)
    w["vision_model.embeddings.patch_embedding.weight"] = normal(
        vw, 3, v["patch_size"], v["patch_size"], std=0.05)
    w["vision_model.embeddings.position_embedding.weight"] = normal(patches + 1, vw)
    w["vision_model.pre_layrnorm.weight"] = 1 + normal(vw)
    w["vision_model.pre_layrnorm.bias"] = normal(vw)
    layers("vision_model", vw, v["intermediate_size"], v["num_hidden_layers"])
    w["vision_model.post_layernorm.weight"] = 1 + normal(vw)
    w["vision_model.post_layernorm.bias"] = normal(vw)
    w["text_model.embeddings.token_embedding.weight"] = normal(vocab_size, tw, std=0.5)
    w["text_model.embeddings.position_embedding.weight"] = normal(
        t["max_position_embeddings"], tw)
    layers("text_model", tw, t["intermediate_size"], t["num_hidden_layers"])
    w["text_model.final_layer_norm.weight"] = 1 + normal(tw)
    w["text_model.final_layer_norm.bias"] = normal(tw)
    w["visual_projection.weight"] = normal(PROJECTION_DIM, vw, std=1 / math.sqrt(vw))
    w["text_projection.weight"] = normal(PROJECTION_DIM, tw, std=1 / math.sqrt(tw))
    w["logit_scale"] = torch.tensor(math.log(1 / 0.07))
    return {k: x.float().contiguous() for k, x in w.items()}


def layer_norm(x, w, prefix):
    return torch.nn.functional.layer_norm(x, x.shape[-1:], w[prefix + ".weight"],
                                          w[prefix + ".bias"], eps=1e-5)


def linear(x, w, prefix, bias=True):
    y = x @ w[prefix + ".weight"].T
    return y + w[prefix + ".bias"] if bias else y


def encoder(x, w, prefix, heads, count, causal):
    tokens, width = x.shape
    d = width // heads
    for i in range(count):
        p = f"{prefix}.encoder.layers.{i}."
        h = layer_norm(x, w, p + "layer_norm1")
        q = linear(h, w, p + "self_attn.q_proj") * d ** -0.5
        k = linear(h, w, p + "self_attn.k_proj")
        v = linear(h, w, p + "self_attn.v_proj")
        q, k, v = (t.reshape(tokens, heads, d).transpose(0, 1) for t in (q, k, v))
        scores = q @ k.transpose(1, 2)
        if causal:
            mask = torch.triu(torch.ones(tokens, tokens, dtype=torch.bool), 1)
            scores = scores.masked_fill(mask, float("-inf"))
        o = (scores.softmax(-1) @ v).transpose(0, 1).reshape(tokens, width)
        x = x + linear(o, w, p + "self_attn.out_proj")
        h = linear(layer_norm(x, w, p + "layer_norm2"), w, p + "mlp.fc1")
        h = h * torch.sigmoid(1.702 * h)  # QuickGELU
        x = x + linear(h, w, p + "mlp.fc2")
    return x


def encode_image(pixels, w):
    v = VISION
    patch = w["vision_model.embeddings.patch_embedding.weight"]
    x = torch.nn.functional.conv2d(pixels[None], patch, stride=v["patch_size"])[0]
    x = x.flatten(1).T
    x = torch.cat([w["vision_model.embeddings.class_embedding"][None], x])
    x = x + w["vision_model.embeddings.position_embedding.weight"]
    x = layer_norm(x, w, "vision_model.pre_layrnorm")
    x = encoder(x, w, "vision_model", v["num_attention_heads"], v["num_hidden_layers"], False)
    pooled = layer_norm(x[0], w, "vision_model.post_layernorm")
    return linear(pooled, w, "visual_projection", bias=False)


def encode_text(ids, w, eot_id):
    t = TEXT
    ids_t = torch.tensor(ids)
    x = w["text_model.embeddings.token_embedding.weight"][ids_t]
    x = x + w["text_model.embeddings.position_embedding.weight"][: len(ids)]
    x = encoder(x, w, "text_model", t["num_attention_heads"], t["num_hidden_layers"], True)
    x = layer_norm(x, w, "text_model.final_layer_norm")
    pooled = x[ids.index(eot_id)]
    return linear(pooled, w, "text_projection", bias=False)


# ------------------------------------------------------------------- files

def write_safetensors(path, tensors):
    header, offset, blobs = {}, 0, []
    for name in sorted(tensors):
        data = tensors[name].numpy().astype("<f4").tobytes()
        header[name] = {"dtype": "F32", "shape": list(tensors[name].shape),
                        "data_offsets": [offset, offset + len(data)]}
        offset += len(data)
        blobs.append(data)
    header["__metadata__"] = {"format": "pt"}
    text = json.dumps(header, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 8)
    with open(path, "wb") as f:
        f.write(struct.pack("<Q", len(text)))
        f.write(text)
        for b in blobs:
            f.write(b)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(__file__), "..", "tests", "fixtures", "tiny_clip")
    os.makedirs(out, exist_ok=True)
    gen = torch.Generator().manual_seed(SEED)

    merges = learn_merges(CORPUS, NUM_MERGES)
    symbols = list(bytes_to_unicode().values())
    vocab_list = symbols + [s + "</w>" for s in symbols] + ["".join(m) for m in merges]
    vocab_list += ["<|startoftext|>", "<|endoftext|>"]
    vocab = {s: i for i, s in enumerate(vocab_list)}
    with open(os.path.join(out, "vocab.json"), "w", encoding="utf-8") as f:
        json.dump(vocab, f, ensure_ascii=False)
    with open(os.path.join(out, "merges.txt"), "w", encoding="utf-8") as f:
        f.write("#version: 0.2\n" + "".join(f"{a} {b}\n" for a, b in merges))
    tokenizer = Tokenizer(vocab, merges)

    w = random_weights(len(vocab), gen)
    write_safetensors(os.path.join(out, "model.safetensors"), w)
    config = {"architectures": ["CLIPModel"], "model_type": "clip",
              "projection_dim": PROJECTION_DIM,
              "text_config": dict(TEXT, vocab_size=len(vocab), hidden_act="quick_gelu",
                                  layer_norm_eps=1e-5),
              "vision_config": dict(VISION, hidden_act="quick_gelu", layer_norm_eps=1e-5)}
    with open(os.path.join(out, "config.json"), "w") as f:
        json.dump(config, f, indent=2)

    w64 = {k: x.double() for k, x in w.items()}
    size = VISION["image_size"]
    images = [torch.randn(3, size, size, generator=gen) for _ in range(2)]
    eot = vocab["<|endoftext|>"]
    reference = {
        "tokens": [{"text": s, "ids": tokenizer.encode(s)} for s in TRICKY_STRINGS],
        "images": [{"pixels": img.flatten().tolist(),
                    "embedding": encode_image(img.double(), w64).tolist()} for img in images],
        "texts": [{"text": s, "ids": tokenizer.encode(s),
                   "embedding": encode_text(tokenizer.encode(s), w64, eot).tolist()}
                  for s in TEXTS_TO_ENCODE],
    }
    with open(os.path.join(out, "reference.json"), "w", encoding="utf-8") as f:
        json.dump(reference, f, ensure_ascii=False)
    print(f"tiny CLIP ({len(vocab)} tokens, {len(merges)} merges) written to {out}")


if __name__ == "__main__":
    main()
